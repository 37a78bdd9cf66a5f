// The episode viewer (`dicestack dataset view`): dataset_viewer.hpp says what it holds.
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include <dicestack/core/geometry.hpp>
#include <dicestack/pages/dataset_viewer.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/pages/page.hpp>
#include <dicestack/pages/resources.hpp>
#include <dicestack/version.hpp>


namespace dicestack {
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kViewerFormat = "dicestack-viewer-media";
constexpr const char* kViewerMarker = "dicestack-page.json";

// Numbers rounded to 0.1 mm / 0.1 mrad: what a plot or a drawing can show, a third of the text.
json rounded(double v) { return std::round(v * 1e4) / 1e4; }

std::string episode_script(std::size_t index) {
  char s[48];
  std::snprintf(s, sizeof s, "episodes/episode_%06zu.js", index);
  return s;
}

// One episode's numbers as the script the page loads: per step the cup's x, y, angle, each
// die's x, y, angle (the drawing and the plots), and the action.
std::string episode_data(const Episode& e, std::size_t index) {
  json steps = json::array();
  for (std::size_t t = 0; t < e.states.size(); ++t) {
    const State& s = e.states[t];
    json row = json::array();
    for (std::size_t k : {state_index::kCupX, state_index::kCupY, state_index::kCupAngle}) row.push_back(rounded(s[k]));
    for (std::size_t d = 0; d < kDiceCount; ++d)
      for (std::size_t k = 0; k < 3; ++k) row.push_back(rounded(s[state_index::die(d) + k]));
    for (double a : e.actions[t]) row.push_back(rounded(a));
    steps.push_back(std::move(row));
  }
  return "dicestackEpisode(" + std::to_string(index) + ", " + page::script_safe(json{{"steps", steps}}.dump()) + ");\n";
}

// What the drawing needs of the world: walls, the cup's segments about its centre of mass, the
// die's outline about its centre, and the control step.
json world_json(const WorldConfig& w) {
  json cup = json::array();
  for (const RoundedSegment& s : cup_geometry(w.cup).segments) cup.push_back({s.a.x, s.a.y, s.b.x, s.b.y, s.radius});
  json die = json::array();
  for (const Vec2& v : die_vertices(w.dice)) die.push_back({v.x, v.y});
  return {{"left", w.walls.left_x},   {"right", w.walls.right_x}, {"floor", w.walls.floor_y},
          {"ceiling", w.walls.ceiling_y}, {"radius", w.walls.radius}, {"cup", cup},
          {"die", die},               {"dt", w.physics.control_dt}};
}

std::string viewer_html(const DemoSet& set, const std::string& name, const std::string& media) {
  json list = json::array();
  for (std::size_t i = 0; i < set.episodes.size(); ++i) {
    const Episode& e = set.episodes[i];
    list.push_back({{"name", e.name},
                    {"steps", e.size()},
                    {"success", e.outcome.realistic_success()},
                    {"stacked", e.outcome.stacked},
                    {"wall_contact", e.outcome.wall_contact},
                    {"dice_in_cup", e.outcome.dice_in_cup},
                    {"origin", e.origin},
                    {"script", media + "/" + episode_script(i)}});
  }
  const auto& w = set.world.walls;
  const int width = 450, height = static_cast<int>(std::lround(width * (w.ceiling_y + w.left_x) / (w.right_x + w.left_x)));
  const json data{{"title", "dicestack episodes: " + name},
                  {"facts", std::to_string(set.episodes.size()) + " episodes. " + set.description},
                  {"provenance", set.provenance},
                  {"world", world_json(set.world)},
                  {"episodes", list}};
  std::string page = "<!doctype html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  page += "<meta name=\"generator\" content=\"dicestack " DICESTACK_VERSION "\">\n<title>dicestack episodes</title>\n<style>";
  page += page::resource::viewer_css;
  page += "</style>\n</head>\n<body>\n<h1 id=\"title\"></h1>\n<p id=\"facts\"></p>\n<details id=\"made\"><summary>how the set was made</summary><p id=\"provenance\"></p></details>\n<main>\n<div id=\"list\"><table><thead><tr>"
          "<th>#</th><th>episode</th><th>steps</th><th>realistic success</th><th>stacked</th><th>wall contact</th>"
          "<th>dice in cup</th><th>origin</th></tr></thead><tbody></tbody></table></div>\n<div id=\"player\">\n"
          "<strong id=\"name\"></strong>\n<canvas id=\"scene\" width=\"" +
          std::to_string(width) + "\" height=\"" + std::to_string(height) +
          "\"></canvas>\n<div id=\"controls\"><button id=\"play\" type=\"button\">play</button>"
          "<input id=\"slider\" type=\"range\" min=\"0\" max=\"0\" value=\"0\"><span id=\"step\"></span></div>\n"
          "<div id=\"plots\"><canvas id=\"chart\" width=\"620\" height=\"520\"></canvas><div id=\"cursor\"></div></div>\n"
          "</div>\n</main>\n<script type=\"application/json\" id=\"page-data\">";
  page += page::script_safe(data.dump());
  page += "</script>\n<script>";
  page += page::resource::viewer_js;
  page += "</script>\n</body>\n</html>\n";
  return page;
}

}  // namespace

void write_dataset_viewer(const DemoSet& set, const std::string& name, const fs::path& page_path) {
  // The page plots the cup's actions (dvx, dvy, dw); an episode in joint torques has none.
  for (const Episode& e : set.episodes)
    if (!e.actions.empty() && e.actions.front().kind() != ActionKind::cup)
      throw InputError(name + ": episode " + e.name + " acts in joint torques; the episode viewer plots the cup's actions");
  const page::MediaFolder media{page_media_folder(page_path), kViewerMarker, kViewerFormat, "episode viewer's folder"};
  page::write_page_with_media(
      page_path, results_page_ownership(), media,
      [&](const fs::path& folder) {
        fs::create_directories(folder / "episodes");
        for (std::size_t i = 0; i < set.episodes.size(); ++i) {
          AtomicFile f(folder / episode_script(i), Ownership::unchecked("episode data"), AtomicFile::Leftovers::skip);
          f.stream() << episode_data(set.episodes[i], i);
          f.commit();
        }
      },
      [&](const std::string& media_url) {
        return std::string(kResultsPageMarker) + "\n" + viewer_html(set, name, media_url);
      });
}

}  // namespace dicestack
