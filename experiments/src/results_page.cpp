#include <dicestack/experiments/results_page.hpp>

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/video.hpp>
#include <dicestack/version.hpp>

#include <dicestack/pages/page.hpp>
#include <dicestack/pages/resources.hpp>

namespace dicestack {
namespace fs = std::filesystem;
using nlohmann::json;
using page::check_marked_folder;
using page::is_marked_folder;
using page::write_marker;

namespace {

constexpr const char* kMediaFormat = "dicestack-page-media";
constexpr const char* kMediaMarker = "dicestack-page.json";
constexpr const char* kReportFormat = "dicestack-report";
constexpr const char* kReportMarker = "dicestack-report.json";
// Previews: half the window's scale, a frame every second control step (15 frames/s).
constexpr double kPreviewPixelsPerMetre = 50.0;
constexpr int kPreviewEvery = 2;
constexpr int kPreviewWidth = 225;  // shown at half the size drawn (450 px wide): sharp on dense screens

// "row-07": a row's files, numbered in table order with as many digits as the last needs.
std::string row_name(std::size_t index, std::size_t rows) {
  const std::size_t digits = std::max<std::size_t>(2, std::to_string(rows).size());
  std::string number = std::to_string(index + 1);
  if (number.size() < digits) number.insert(0, digits - number.size(), '0');
  return "row-" + number;
}

bool learned(const LeaderboardRow& r) { return !r.rollouts.empty(); }

// LeRobot's eval_info.json for one row: per_episode, aggregated, video_paths; and which row.
json eval_info(const LeaderboardRow& row, const std::vector<std::string>& videos) {
  json per = json::array();
  double reward = 0.0;
  int successes = 0;
  for (std::size_t i = 0; i < row.rollouts.size(); ++i) {
    const EpisodeResult& e = row.rollouts[i].result;
    per.push_back({{"episode_ix", i},
                   {"training_seed", row.rollouts[i].training_seed},
                   {"index", e.index},
                   {"seed", e.seed},
                   {"success", e.success},
                   {"stacked", e.stacked},
                   {"wall_contact", e.wall_contact},
                   {"dice_in_cup", e.dice_in_cup},
                   {"wall_step", e.wall_step < 0 ? json(nullptr) : json(e.wall_step)},
                   {"length", e.length},
                   {"sum_reward", e.reward}});
    reward += e.reward;
    successes += e.success;
  }
  const double n = std::max<double>(1.0, static_cast<double>(row.rollouts.size()));
  const Rate rs = wilson(successes, static_cast<int>(row.rollouts.size()));
  return {{"format", "dicestack-eval-info"},
          {"version", 1},
          {"row", {{"regressor", row.regressor}, {"learner", row.learner}, {"features", row.features}}},
          {"per_episode", std::move(per)},
          {"aggregated",
           {{"n_episodes", row.rollouts.size()},
            {"pc_success", 100.0 * successes / n},
            {"pc_success_ci95", {100.0 * rs.low, 100.0 * rs.high}},
            {"avg_sum_reward", reward / n}}},
          {"video_paths", videos}};
}

std::string preview_file(std::size_t index, std::size_t rows, const char* kind) {
  return "previews/" + row_name(index, rows) + "-" + kind + ".gif";
}

}  // namespace

namespace {

// The media into an empty folder.
void fill_media(const Leaderboard& board, const fs::path& folder) {
  const std::size_t rows = board.rows.size();
  fs::create_directories(folder / "eval_info");
  fs::create_directories(folder / "previews");
  // Every preview to draw: (row, kind, states); drawn in parallel, the same files on any thread count.
  struct PreviewJob {
    std::size_t row;
    const char* kind;
    const RowPreview* preview;
  };
  std::vector<PreviewJob> jobs;
  for (std::size_t i = 0; i < rows; ++i) {
    const LeaderboardRow& r = board.rows[i];
    for (const RowPreview& p : r.success_preview) jobs.push_back({i, "success", &p});
    for (const RowPreview& p : r.failure_preview) jobs.push_back({i, "failure", &p});
  }
  FrameOptions frames;
  frames.render.pixels_per_metre = kPreviewPixelsPerMetre;
  frames.every = kPreviewEvery;
  parallel_for(jobs.size(), 0, [&](std::size_t j, int) {
    const PreviewJob& job = jobs[j];
    const LeaderboardRow& r = board.rows[job.row];
    const std::string title = r.learner + " " + r.regressor + ": " + job.kind;
    write_frames(job.preview->states, board.world, title, folder / preview_file(job.row, rows, job.kind), frames);
  });
  for (std::size_t i = 0; i < rows; ++i) {
    const LeaderboardRow& r = board.rows[i];
    if (!learned(r)) continue;
    std::vector<std::string> videos;
    if (!r.success_preview.empty()) videos.push_back(preview_file(i, rows, "success"));
    if (!r.failure_preview.empty()) videos.push_back(preview_file(i, rows, "failure"));
    AtomicFile f(folder / "eval_info" / (row_name(i, rows) + ".json"), Ownership::unchecked("eval info"), AtomicFile::Leftovers::skip);
    f.stream() << eval_info(r, videos).dump(2) << '\n';
    f.commit();
  }
  write_marker(folder / kMediaMarker, kMediaFormat);
}

}  // namespace

std::string results_page_html(const Leaderboard& board, const std::string& media) {
  const json meta = json::parse(board.meta_json);
  json facts = json::array();
  for (auto it = meta.begin(); it != meta.end(); ++it) facts.push_back({it.key(), it.value()});
  if (!board.demos_description.empty()) facts.push_back({"demonstrations' description", board.demos_description});
  const auto& w = board.world.walls;
  const double aspect = (w.ceiling_y + w.left_x) / (w.right_x + w.left_x);
  json rows = json::array();
  const std::string prefix = media.empty() ? "" : media + "/";
  for (std::size_t i = 0; i < board.rows.size(); ++i) {
    const LeaderboardRow& r = board.rows[i];
    json row = json::parse(leaderboard_row_json(r));
    row["rank"] = i + 1;
    row["has_rollouts"] = learned(r);
    row["eval_info"] = media.empty() || !learned(r) ? json(nullptr) : json(prefix + "eval_info/" + row_name(i, board.rows.size()) + ".json");
    json previews = json::object();
    auto put = [&](const char* kind, const std::vector<RowPreview>& v) {
      if (v.empty() || media.empty()) return;
      previews[kind] = {{"src", prefix + preview_file(i, board.rows.size(), kind)},
                        {"training_seed", v[0].training_seed},
                        {"index", v[0].index},
                        {"seed", std::to_string(v[0].seed)}};  // a string: JavaScript numbers hold 53 bits
    };
    put("success", r.success_preview);
    put("failure", r.failure_preview);
    row["previews"] = std::move(previews);
    rows.push_back(std::move(row));
  }
  const std::string title = meta.contains("model") ? "dicestack evaluation: " + meta.at("model").get<std::string>()
                                                   : "dicestack leaderboard";
  const json data{{"title", title},
                  {"header", board.header},
                  {"facts", facts},
                  {"preview", {{"width", kPreviewWidth}, {"height", static_cast<int>(std::lround(kPreviewWidth * aspect))}}},
                  {"rows", rows}};
  return page::table_page_html(data.dump(), page::resource::leaderboard_js);
}

void check_page_media_replaceable(const fs::path& folder) {
  check_marked_folder(folder, kMediaMarker, kMediaFormat, "results page's media folder");
}

void write_results_page(const Leaderboard& board, const fs::path& page) {
  const page::MediaFolder media{page_media_folder(page), kMediaMarker, kMediaFormat, "results page's media folder"};
  page::write_page_with_media(
      page, results_page_ownership(), media, [&](const fs::path& folder) { fill_media(board, folder); },
      [&](const std::string& media_url) {
        return std::string(kResultsPageMarker) + "\n" + results_page_html(board, media_url);
      });
}

void check_report_replaceable(const fs::path& dir) {
  check_marked_folder(dir, kReportMarker, kReportFormat, "evaluation report");
}

void write_report_folder(const Leaderboard& board, const fs::path& dir) {
  replace_folder(
      dir, [](const fs::path& p) { return is_marked_folder(p, kReportMarker, kReportFormat); }, check_report_replaceable,
      [&](const fs::path& tmp) {
        fill_media(board, tmp / "index_files");
        AtomicFile page(tmp / "index.html", results_page_ownership(), AtomicFile::Leftovers::skip);
        page.stream() << kResultsPageMarker << '\n' << results_page_html(board, "index_files");
        page.commit();
        write_marker(tmp / kReportMarker, kReportFormat);
      });
}

}  // namespace dicestack
