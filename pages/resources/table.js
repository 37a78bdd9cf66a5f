
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
