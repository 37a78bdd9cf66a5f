
const levels = ["none", "easy", "medium", "hard"];
sortableTable([
  { key: "rank", label: "#", value: (r) => r.rank, text: (r) => String(r.rank) },
  { key: "factor", label: "factor" },
  { key: "level", label: "level", value: (r) => levels.indexOf(r.level), text: (r) => r.level, className: "level" },
  Object.assign({ key: "realistic_success_rate", label: "realistic success" }, rate("realistic_success")),
  { key: "successes", label: "successes", value: (r) => r.successes, text: (r) => r.successes + " of " + r.episodes },
  Object.assign({ key: "wall_contact_rate", label: "wall contact" }, rate("wall_contact")),
  { key: "dice_in_cup_mean", label: "dice in cup", value: (r) => r.dice_in_cup_mean, text: (r) => fixed(2)(r.dice_in_cup_mean) },
  { key: "episodes", label: "rollouts", value: (r) => r.episodes, text: (r) => String(r.episodes) },
], { heads: [], cells: () => [] });
