// The leaderboard's formats: each one's text, the files it may replace and how it is written
// (leaderboard.hpp, LeaderboardFormat).
#include <dicestack/experiments/leaderboard.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/experiments/results_page.hpp>

#include "leaderboard_json.hpp"

namespace dicestack {
namespace {

using nlohmann::json;

std::string pct(int k, int n) {
  const Rate r = wilson(k, n);
  char s[64];
  std::snprintf(s, sizeof s, "%.0f%% [%.0f-%.0f]", 100 * r.value, 100 * r.low, 100 * r.high);
  return s;
}

std::string fixed(double v, int digits) {
  if (v < 0) return "-";
  char s[32];
  std::snprintf(s, sizeof s, "%.*f", digits, v);
  return s;
}

constexpr const char* kCsvHeader =
    "regressor,learner,features,train_error,test_error,dice_in_cup_mean,stacked_rate,stacked_low,stacked_high,"
    "wall_contact_rate,realistic_success_rate,realistic_success_low,realistic_success_high,episodes,fit_s,us_per_step";
// The header before feature maps had a column (still ours to replace).
constexpr const char* kCsvHeaderV1 =
    "regressor,learner,train_error,test_error,dice_in_cup_mean,stacked_rate,stacked_low,stacked_high,"
    "wall_contact_rate,realistic_success_rate,realistic_success_low,realistic_success_high,episodes,fit_s,us_per_step";

Ownership md_ownership(const std::string& format, const std::string& marker) {
  // Our marker line, or the header line tables had before the marker.
  return {"dicestack leaderboard (" + format + ")", [marker, format](const std::filesystem::path& p) {
            std::ifstream in(p, std::ios::binary);
            std::string first;
            std::getline(in, first);
            const std::string old = format == "latex" ? "% dicestack " : "dicestack ";
            return first == marker || (first.rfind(old, 0) == 0 && first.find(" leaderboard: ") != std::string::npos);
          }};
}


const std::vector<std::string> kColumns{"regressor", "learner", "features", "train error", "test error", "dice in cup",
                                        "stacked", "wall contact", "realistic success", "fit s", "us/step"};

std::vector<std::string> cells(const LeaderboardRow& r) {
  return {r.regressor, r.learner, r.features, fixed(r.train_error, 3), fixed(r.test_error, 3),
          fixed(r.dice_in_cup, 2), pct(r.stacked, r.episodes), pct(r.walls, r.episodes),
          pct(r.success, r.episodes), fixed(r.fit_s, 2), fixed(r.us_per_step, 1)};
}

std::string render_json(const Leaderboard& board) {
  json j = json::parse(board.meta_json);
  j["format"] = kLeaderboardFormat;
  j["version"] = 1;
  j["rows"] = json::array();
  for (const auto& r : board.rows) j["rows"].push_back(leaderboard_row_object(r));
  return j.dump(2) + '\n';
}

std::string render_csv(const Leaderboard& board) {
  std::ostringstream os;
  os << kCsvHeader << '\n';
  for (const auto& r : board.rows) {
    const Rate st = wilson(r.stacked, r.episodes), wc = wilson(r.walls, r.episodes), rs = wilson(r.success, r.episodes);
    os << r.regressor << ',' << r.learner << ',' << r.features << ',' << r.train_error << ',' << r.test_error << ',' << r.dice_in_cup << ','
       << st.value << ',' << st.low << ',' << st.high << ',' << wc.value << ',' << rs.value << ',' << rs.low << ','
       << rs.high << ',' << r.episodes << ',' << r.fit_s << ',' << r.us_per_step << '\n';
  }
  return os.str();
}

std::string render_latex(const Leaderboard& board) {
  std::ostringstream os;
  os << "% " << board.header << "\n\\begin{tabular}{lllrrrrrrrr}\n\\hline\n";
  for (std::size_t c = 0; c < kColumns.size(); ++c) os << kColumns[c] << (c + 1 < kColumns.size() ? " & " : " \\\\\n\\hline\n");
  for (const auto& r : board.rows) {
    const auto v = cells(r);
    for (std::size_t c = 0; c < v.size(); ++c) {
      std::string cell = v[c];
      for (std::size_t p = 0; (p = cell.find_first_of("%_", p)) != std::string::npos; p += 2) cell.insert(p, "\\");
      os << cell << (c + 1 < v.size() ? " & " : " \\\\\n");
    }
  }
  os << "\\hline\n\\end{tabular}\n";
  return os.str();
}

std::string render_md(const Leaderboard& board) {
  std::ostringstream os;
  os << board.header << "\n\n|";
  for (const auto& c : kColumns) os << ' ' << c << " |";
  os << "\n|";
  for (std::size_t c = 0; c < kColumns.size(); ++c) os << (c < 3 ? "---|" : "---:|");
  os << '\n';
  for (const auto& r : board.rows) {
    os << '|';
    for (const auto& v : cells(r)) os << ' ' << v << " |";
    os << '\n';
  }
  return os.str();
}


}  // namespace

const std::vector<LeaderboardFormat>& leaderboard_formats() {
  static const std::vector<LeaderboardFormat> formats = [] {
    using Path = const std::filesystem::path&;
    auto text = [](std::string (*render)(const Leaderboard&)) { return [render](const Leaderboard& b, Path) { return render(b); }; };
    std::vector<LeaderboardFormat> f;
    f.push_back({"md", ".md", "the header line, then a Markdown table", text(render_md),
                 [] { return md_ownership("md", "<!-- dicestack leaderboard -->"); }, "<!-- dicestack leaderboard -->\n"});
    f.push_back({"csv", ".csv", "a row per line, rates with their intervals", text(render_csv),
                 [] { return Ownership::first_line("dicestack leaderboard (csv)", {kCsvHeader, kCsvHeaderV1}); }, ""});
    f.push_back({"latex", ".tex", "a tabular, the header line as a comment", text(render_latex),
                 [] { return md_ownership("latex", "% dicestack leaderboard"); }, "% dicestack leaderboard\n"});
    f.push_back({"json", ".json", "the settings and a \"rows\" array", text(render_json),
                 [] { return Ownership::json_object("dicestack leaderboard (json)", kLeaderboardFormat, {"rows", "dicestack_version"}); },
                 ""});
    LeaderboardFormat html{"html", ".html",
                           "a page for a browser: sortable table, previews, per-episode results in <page>_files/ (docs/results-pages.md)",
                           [](const Leaderboard& b, Path) { return results_page_html(b, ""); },
                           [] { return results_page_ownership(); }, std::string(kResultsPageMarker) + "\n"};
    html.write = [](const Leaderboard& b, Path out) { write_results_page(b, out); };
    html.check_beside = [](Path out) { check_page_media_replaceable(page_media_folder(out)); };
    html.echo = "md";
    f.push_back(std::move(html));
    return f;
  }();
  return formats;
}

const LeaderboardFormat& leaderboard_format(const std::string& name) {
  std::vector<std::string> names;
  for (const LeaderboardFormat& f : leaderboard_formats()) {
    if (f.name == name) return f;
    names.push_back(f.name);
  }
  std::string list;
  for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
  throw ConfigError("leaderboard: format \"" + name + "\" is not one of " + list);
}

}  // namespace dicestack
