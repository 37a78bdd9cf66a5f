// The episode viewer (`dicestack dataset view`): results_page.hpp says what it holds.
#include <cmath>
#include <cstdio>

#include <nlohmann/json.hpp>

#include <dicestack/core/geometry.hpp>
#include <dicestack/learners/results_page.hpp>
#include <dicestack/version.hpp>

#include "page_files.hpp"

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

constexpr const char* kStyle = R"CSS(
body { font: 14px/1.4 system-ui, sans-serif; margin: 1.2em; color: #222; }
h1 { font-size: 1.3em; margin: 0 0 .2em; }
#facts, #made { color: #555; font-size: .9em; margin: 0 0 .8em; }
main { display: flex; gap: 1.2em; align-items: flex-start; }
#list { max-height: 85vh; overflow-y: auto; border: 1px solid #ddd; }
#list table { border-collapse: collapse; font-size: .85em; }
#list th { position: sticky; top: 0; background: #f4f4f4; }
#list th, #list td { padding: .15em .5em; text-align: left; border-bottom: 1px solid #eee; white-space: nowrap; }
#list tr.chosen td { background: #dbeafe; }
#list tbody tr { cursor: pointer; }
.yes { color: #1a7f37; } .no { color: #999; } .wall { color: #c62828; }
#player { display: flex; flex-direction: column; gap: .4em; }
#controls { display: flex; gap: .6em; align-items: center; }
#plots { position: relative; }
#cursor { position: absolute; top: 0; width: 2px; background: #e11d48; pointer-events: none; }
)CSS";

constexpr const char* kScript = R"JS(
"use strict";
const data = JSON.parse(document.getElementById("page-data").textContent);
const W = data.world;
const episodes = new Map();  // index -> its steps, once its script has run
let chosen = -1, playing = false, step = 0, clock = 0;
function el(tag, attrs, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  for (const c of children) e.append(c);
  return e;
}
document.getElementById("title").textContent = data.title;
document.getElementById("facts").textContent = data.facts;
document.getElementById("provenance").textContent = data.provenance;
document.getElementById("made").hidden = !data.provenance;
const body = document.querySelector("#list tbody");
const mark = (v, cls) => el("span", { class: v ? cls : "no" }, v ? "yes" : "no");
data.episodes.forEach((e, i) => {
  const tr = el("tr", { "data-index": i },
    el("td", {}, String(i)), el("td", {}, e.name), el("td", {}, String(e.steps)),
    el("td", {}, mark(e.success, "yes")), el("td", {}, mark(e.stacked, "yes")), el("td", {}, mark(e.wall_contact, "wall")),
    el("td", {}, String(e.dice_in_cup)), el("td", {}, e.origin));
  tr.addEventListener("click", () => choose(i));
  body.append(tr);
});
const scene = document.getElementById("scene"), sctx = scene.getContext("2d");
const plots = document.getElementById("plots"), chart = document.getElementById("chart"), cctx = chart.getContext("2d");
const cursor = document.getElementById("cursor"), slider = document.getElementById("slider");
const label = document.getElementById("step"), button = document.getElementById("play");
const ppm = scene.width / (W.right + W.left);
const px = (x, y) => [x * ppm, scene.height - y * ppm];
const dieColours = ["#dc5050", "#3caa50", "#2878c8"];
function turn(cx, cy, a, x, y) { return [cx + Math.cos(a) * x - Math.sin(a) * y, cy + Math.sin(a) * x + Math.cos(a) * y]; }
function draw(s) {
  sctx.fillStyle = "#ebf0f5"; sctx.fillRect(0, 0, scene.width, scene.height);
  sctx.fillStyle = "#5a5a5a";
  const r = W.radius;
  for (const [x0, y0, x1, y1] of [[W.left - r, W.floor - r, W.right + r, W.floor + r], [W.left - r, W.floor - r, W.left + r, W.ceiling + r],
                                  [W.right - r, W.floor - r, W.right + r, W.ceiling + r], [W.left - r, W.ceiling - r, W.right + r, W.ceiling + r]]) {
    const [a, b] = px(x0, y1), [c, d] = px(x1, y0);
    sctx.fillRect(a, b, c - a, d - b);
  }
  sctx.strokeStyle = "#c86e28"; sctx.lineCap = "round";
  for (const [ax, ay, bx, by, rad] of W.cup) {
    sctx.lineWidth = 2 * rad * ppm;
    sctx.beginPath(); sctx.moveTo(...px(...turn(s[0], s[1], s[2], ax, ay))); sctx.lineTo(...px(...turn(s[0], s[1], s[2], bx, by))); sctx.stroke();
  }
  for (let d = 0; d < 3; ++d) {
    const [x, y, a] = [s[3 + 3 * d], s[4 + 3 * d], s[5 + 3 * d]];
    sctx.beginPath();
    W.die.forEach(([vx, vy], k) => { const p = px(...turn(x, y, a, vx, vy)); if (k) sctx.lineTo(...p); else sctx.moveTo(...p); });
    sctx.closePath(); sctx.fillStyle = "#fafafa"; sctx.fill(); sctx.lineWidth = 2; sctx.strokeStyle = dieColours[d]; sctx.stroke();
  }
}
// Panels: [title, [[series index, colour, name], ...]]; series are columns of a step's row.
const panels = [["cup x, y (m)", [[0, "#c86e28", "x"], [1, "#7c3aed", "y"]]], ["cup angle (rad)", [[2, "#c86e28", "angle"]]],
                ["dice heights (m)", [[4, dieColours[0], "die 0"], [7, dieColours[1], "die 1"], [10, dieColours[2], "die 2"]]],
                ["actions", [[12, "#0f766e", "dvx"], [13, "#b45309", "dvy"], [14, "#6d28d9", "dw"]]]];
const margin = 46, panelHeight = chart.height / panels.length;
function plot(steps) {
  cctx.clearRect(0, 0, chart.width, chart.height);
  cctx.font = "12px system-ui, sans-serif";
  const n = steps.length, x = (t) => margin + (chart.width - margin - 8) * t / Math.max(1, n - 1);
  panels.forEach(([title, series], p) => {
    const top = p * panelHeight + 16, h = panelHeight - 30;
    let lo = Infinity, hi = -Infinity;
    for (const [k] of series) for (const row of steps) { lo = Math.min(lo, row[k]); hi = Math.max(hi, row[k]); }
    if (hi - lo < 1e-9) { hi += 0.5; lo -= 0.5; }
    const y = (v) => top + h * (1 - (v - lo) / (hi - lo));
    cctx.fillStyle = "#333"; cctx.fillText(title, margin, top - 4);
    cctx.fillStyle = "#777"; cctx.fillText(hi.toPrecision(3), 2, top + 10); cctx.fillText(lo.toPrecision(3), 2, top + h);
    cctx.strokeStyle = "#ddd"; cctx.lineWidth = 1; cctx.strokeRect(margin, top, chart.width - margin - 8, h);
    series.forEach(([k, colour, name], i) => {
      cctx.strokeStyle = colour; cctx.lineWidth = 1.5; cctx.beginPath();
      steps.forEach((row, t) => (t ? cctx.lineTo(x(t), y(row[k])) : cctx.moveTo(x(t), y(row[k]))));
      cctx.stroke();
      cctx.fillStyle = colour; cctx.fillText(name, chart.width - 60 - 50 * (series.length - 1 - i), top - 4);
    });
  });
}
function show(t) {
  const steps = episodes.get(chosen);
  if (!steps) return;
  step = Math.max(0, Math.min(steps.length - 1, t));
  draw(steps[step]);
  const n = steps.length;
  cursor.style.left = (margin + (chart.width - margin - 8) * step / Math.max(1, n - 1)) + "px";
  cursor.dataset.step = String(step);
  slider.value = String(step);
  label.textContent = "step " + step + " of " + (n - 1) + ", t = " + (step * W.dt).toFixed(2) + " s";
}
window.dicestackEpisode = (index, episode) => {
  episodes.set(index, episode.steps);
  if (index === chosen) { slider.max = String(episode.steps.length - 1); plot(episode.steps); show(0); document.body.dataset.loaded = String(index); }
};
function choose(i) {
  if (chosen >= 0) body.children[chosen].classList.remove("chosen");
  chosen = i; playing = false; button.textContent = "play";
  body.children[i].classList.add("chosen");
  document.getElementById("name").textContent = data.episodes[i].name;
  if (episodes.has(i)) window.dicestackEpisode(i, { steps: episodes.get(i) });
  else {
    const script = el("script", { src: data.episodes[i].script });
    script.addEventListener("error", () => {  // the page moved without its folder
      if (chosen === i) document.getElementById("name").textContent = data.episodes[i].name + ": its data (" +
        data.episodes[i].script + ") is missing; keep the _files folder beside the page";
    });
    document.head.append(script);
  }
}
function tick(now) {
  if (!playing) return;
  const steps = episodes.get(chosen);
  const t = Math.floor((now - clock) / 1000 / W.dt);
  if (t >= steps.length) { playing = false; button.textContent = "play"; show(steps.length - 1); return; }
  show(t);
  requestAnimationFrame(tick);
}
function play() {
  if (!episodes.has(chosen)) return;
  if (step >= episodes.get(chosen).length - 1) step = 0;
  playing = true; button.textContent = "pause";
  clock = performance.now() - step * W.dt * 1000;
  requestAnimationFrame(tick);
}
button.addEventListener("click", () => (playing ? ((playing = false), (button.textContent = "play")) : play()));
slider.addEventListener("input", () => { playing = false; button.textContent = "play"; show(Number(slider.value)); });
cursor.style.height = chart.height + "px";
if (data.episodes.length) choose(0);
document.body.dataset.readyAt = String(performance.now());
document.body.dataset.ready = "true";
)JS";

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
  page += kStyle;
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
  page += kScript;
  page += "</script>\n</body>\n</html>\n";
  return page;
}

}  // namespace

void write_dataset_viewer(const DemoSet& set, const std::string& name, const fs::path& page_path) {
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
