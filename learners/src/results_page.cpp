#include <dicestack/learners/results_page.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/video.hpp>
#include <dicestack/version.hpp>

#include "page_files.hpp"

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

// The leaderboard's columns and its extra cells (previews, per-episode results); the table
// itself is the shared one (kTableScript).
constexpr const char* kLeaderboardScript = R"JS(
const columns = [
  { key: "rank", label: "#", value: (r) => r.rank, text: (r) => String(r.rank) },
  { key: "regressor", label: "regressor" },
  { key: "learner", label: "learner", text: (r) => breakable(r.learner) },
  { key: "features", label: "features", text: (r) => breakable(r.features) },
  { key: "train_error", label: "train error", value: (r) => r.train_error, text: (r) => fixed(3)(r.train_error) },
  { key: "test_error", label: "test error", value: (r) => r.test_error, text: (r) => fixed(3)(r.test_error) },
  { key: "dice_in_cup_mean", label: "dice in cup", value: (r) => r.dice_in_cup_mean, text: (r) => fixed(2)(r.dice_in_cup_mean) },
  Object.assign({ key: "stacked_rate", label: "stacked" }, rate("stacked")),
  Object.assign({ key: "wall_contact_rate", label: "wall contact" }, rate("wall_contact")),
  Object.assign({ key: "realistic_success_rate", label: "realistic success" }, rate("realistic_success")),
  { key: "episodes", label: "rollouts", value: (r) => r.episodes, text: (r) => String(r.episodes) },
  { key: "fit_s", label: "fit s", value: (r) => r.fit_s, text: (r) => fixed(2)(r.fit_s) },
  { key: "us_per_step", label: "us/step", value: (r) => r.us_per_step, text: (r) => fixed(1)(r.us_per_step) },
];
function preview(row, kind) {
  const p = row.previews && row.previews[kind];
  if (!p) return el("span", { class: "none" }, "no " + (kind === "success" ? "success" : "failure"));
  const img = el("img", { src: p.src, loading: "lazy", width: data.preview.width, height: data.preview.height,
                          alt: kind + ": training seed " + p.training_seed + ", start seed " + p.seed, class: "preview " + kind });
  return el("figure", {}, img, el("figcaption", {}, kind + ", rollout " + p.index + " (seed " + p.training_seed + ")"));
}
sortableTable(columns, {
  heads: ["previews", "results"],
  cells: (r) => {
    const media = el("div", { class: "media" });
    if (r.has_rollouts) media.append(preview(r, "success"), preview(r, "failure"));
    const link = el("td", {});
    if (r.eval_info) link.append(el("a", { href: r.eval_info }, "per episode"));
    return [el("td", {}, media), link];
  },
});
)JS";

}  // namespace

namespace page {
namespace {

// The script every table page shares: reads the inlined data, shows the title, header and facts
// (as text nodes), and sortableTable() builds the table from data.rows and sorts it by the
// column whose header is clicked (again: the other way).
constexpr const char* kTableScript = R"JS(
"use strict";
const data = JSON.parse(document.getElementById("page-data").textContent);
const pct = (v) => Math.round(100 * v) + "%";
const fixed = (digits) => (v) => (v < 0 ? "-" : v.toFixed(digits));
const rate = (key) => ({
  value: (r) => r[key + "_rate"],
  // The interval may go under the rate, whole: the table fits a laptop's width.
  text: (r) => {
    const f = document.createDocumentFragment();
    f.append(pct(r[key + "_rate"]) + " ", el("span", { class: "interval" },
             "[" + pct(r[key + "_ci95"][0]).slice(0, -1) + "-" + pct(r[key + "_ci95"][1]).slice(0, -1) + "]"));
    return f;
  },
  className: "num rate",
});
// `text` with a line break allowed after each "+", "/" and ":" (a feature map's or a learner
// spec's long name).
function breakable(text) {
  const f = document.createDocumentFragment();
  let part = "";
  for (const ch of text) {
    part += ch;
    if (ch === "+" || ch === "/" || ch === ":") { f.append(part, el("wbr")); part = ""; }
  }
  f.append(part);
  return f;
}
function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  for (const c of children) e.append(c);
  return e;
}
document.title = data.title;
document.getElementById("title").textContent = data.title;
// The header line says in one sentence what the facts list (and a few notes besides): on a page
// with facts it is folded under them, not printed twice.
const header = document.getElementById("header");
header.textContent = data.header;
if (data.facts.length > 0) {
  const folded = el("details", { id: "header-line" }, el("summary", {}, "the run in one line"));
  header.replaceWith(folded);
  folded.append(header);
}
const facts = document.getElementById("facts");
for (const [k, v] of data.facts) facts.append(el("dt", {}, k), el("dd", {}, typeof v === "string" ? v : JSON.stringify(v)));
// columns: {key, label, value(row), text(row), className}: value (a number, kept in data-value)
// sorts, text shows (default: the row's field), className styles valued cells (default "num");
// extra: {heads: [labels], cells: (row) => [td, ...]}, after the columns.
function sortableTable(columns, extra) {
  const head = document.querySelector("#board thead tr");
  const body = document.querySelector("#board tbody");
  function render(rows) {
    body.replaceChildren();
    for (const r of rows) {
      const tr = el("tr", { "data-rank": r.rank });
      for (const c of columns) {
        const td = el("td", { "data-key": c.key }, c.text ? c.text(r) : r[c.key]);
        if (c.value) { td.dataset.value = c.value(r); td.className = c.className || "num"; }
        tr.append(td);
      }
      tr.append(...extra.cells(r));
      body.append(tr);
    }
  }
  let sorted = { key: null, dir: 1 };
  for (const c of columns) {
    const th = el("th", { scope: "col", "data-key": c.key, "aria-sort": "none" }, el("button", { type: "button" }, c.label));
    th.querySelector("button").addEventListener("click", () => {
      sorted = { key: c.key, dir: sorted.key === c.key ? -sorted.dir : 1 };
      for (const h of head.children) h.setAttribute("aria-sort", "none");
      th.setAttribute("aria-sort", sorted.dir > 0 ? "ascending" : "descending");
      const value = c.value || ((r) => r[c.key]);
      const rows = data.rows.slice().sort((a, b) => {
        const x = value(a), y = value(b);
        const missing = (v) => typeof v === "number" && v < 0;  // "-": always last
        if (missing(x) !== missing(y)) return missing(x) ? 1 : -1;
        const order = typeof x === "number" ? x - y : String(x).localeCompare(String(y));
        return order !== 0 ? sorted.dir * order : a.rank - b.rank;
      });
      render(rows);
    });
    head.append(th);
  }
  for (const label of extra.heads) head.append(el("th", { scope: "col" }, label));
  render(data.rows);
  document.body.dataset.readyAt = String(performance.now());
  document.body.dataset.ready = "true";
}
)JS";

constexpr const char* kTableStyle = R"CSS(
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; margin: 0 0 .3em; }
#header { color: #555; font-size: .9em; max-width: 80em; }
details#header-line { font-size: .9em; color: #555; margin: .3em 0; } details#header-line summary { cursor: pointer; }
dl#facts { display: grid; grid-template-columns: max-content 1fr; gap: .1em 1em; font-size: .9em; }
dl#facts dt { font-weight: 600; }
dl#facts dd { margin: 0; word-break: break-word; }
table { border-collapse: collapse; margin-top: 1em; }
th, td { border-bottom: 1px solid #ddd; padding: .3em .6em; text-align: left; vertical-align: top; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.rate { white-space: normal; } span.interval { white-space: nowrap; }
th button { font: inherit; font-weight: 600; background: none; border: none; cursor: pointer; padding: 0; }
th[aria-sort="ascending"] button::after { content: " \25B2"; }
th[aria-sort="descending"] button::after { content: " \25BC"; }
div.media { display: flex; gap: .5em; }
figure { margin: 0; }
figcaption, .none { font-size: .8em; color: #666; }
img.preview { display: block; background: #eee; }
@media (max-width: 1700px) { img.preview { width: 150px; height: auto; } figure { max-width: 150px; } }
img.success { outline: 2px solid #2a8; } img.failure { outline: 2px solid #c44; }
)CSS";

}  // namespace

std::string table_page_html(const std::string& data_json, const char* script) {
  std::string html;
  html += "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<meta name=\"generator\" content=\"dicestack " DICESTACK_VERSION "\">\n";
  html += "<title>dicestack results</title>\n<style>";
  html += kTableStyle;
  html += "</style>\n</head>\n<body>\n<h1 id=\"title\"></h1>\n<p id=\"header\"></p>\n<dl id=\"facts\"></dl>\n";
  html += "<table id=\"board\"><thead><tr></tr></thead><tbody></tbody></table>\n";
  html += "<noscript>This page builds its table with JavaScript; the same rows are in the JSON below.</noscript>\n";
  html += "<script type=\"application/json\" id=\"page-data\">";
  html += script_safe(data_json);
  html += "</script>\n<script>";
  html += kTableScript;
  html += script;
  html += "</script>\n</body>\n</html>\n";
  return html;
}

// JSON that may sit inside <script>: no "<", ">" or "&" (only strings can hold them; \u escapes
// read back the same).
std::string script_safe(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<') out += "\\u003c";
    else if (c == '>') out += "\\u003e";
    else if (c == '&') out += "\\u0026";
    else out += c;
  }
  return out;
}

std::string url_segment(const std::string& name) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : name) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

bool is_marked_folder(const fs::path& folder, const char* marker, const char* format) {
  std::error_code ec;
  if (fs::symlink_status(folder, ec).type() != fs::file_type::directory) return false;
  return Ownership::json_object("", format).recognises(folder / marker);
}

void check_marked_folder(const fs::path& folder, const char* marker, const char* format, const std::string& what) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(folder, ec);
  if (!fs::exists(st)) return;
  if (fs::is_symlink(st))
    throw InputError(folder.string() + ": is a symbolic link; refusing to replace it with a " + what);
  if (is_marked_folder(folder, marker, format)) return;
  throw InputError(folder.string() + ": exists and is not a " + what +
                   " dicestack wrote; refusing to replace it: choose another --out or remove it yourself");
}

void write_marker(const fs::path& file, const char* format, int version) {
  AtomicFile f(file, Ownership::json_object("", format), AtomicFile::Leftovers::skip);
  f.stream() << json{{"format", format}, {"version", version}, {"dicestack_version", DICESTACK_VERSION}}.dump(2) << '\n';
  f.commit();
}

}  // namespace page

std::filesystem::path page_media_folder(const fs::path& page) {
  return page.parent_path() / (page.stem().string() + "_files");
}

Ownership results_page_ownership() { return Ownership::first_line("dicestack results page", {kResultsPageMarker}); }

namespace {

// The media into an empty folder.
void fill_media(const Leaderboard& board, const fs::path& folder) {
  const std::size_t rows = board.rows.size();
  fs::create_directories(folder / "eval_info");
  fs::create_directories(folder / "previews");
  // Every preview to draw: (row, kind, states); drawn in parallel, the same files on any thread count.
  struct Job {
    std::size_t row;
    const char* kind;
    const RowPreview* preview;
  };
  std::vector<Job> jobs;
  for (std::size_t i = 0; i < rows; ++i) {
    const LeaderboardRow& r = board.rows[i];
    for (const RowPreview& p : r.success_preview) jobs.push_back({i, "success", &p});
    for (const RowPreview& p : r.failure_preview) jobs.push_back({i, "failure", &p});
  }
  FrameOptions frames;
  frames.render.pixels_per_metre = kPreviewPixelsPerMetre;
  frames.every = kPreviewEvery;
  parallel_for(jobs.size(), 0, [&](std::size_t j, int) {
    const Job& job = jobs[j];
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
  return page::table_page_html(data.dump(), kLeaderboardScript);
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
