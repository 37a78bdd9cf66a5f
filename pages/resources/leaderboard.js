
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
