
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
