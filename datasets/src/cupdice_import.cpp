#include <dicestack/datasets/cupdice_import.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/read_file.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/datasets/replay.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
namespace si = state_index;

constexpr double kPxPerMetre = 100.0;

// The cup's centre of mass in the original's body frame (px): the cup was built from an anchor
// in world coordinates and rotated by pi about its centre of mass, so body origin = 2 x that.
struct Layout {
  CupdiceLayout kind;
  std::size_t columns;
  double com_x, com_y;
};
constexpr Layout kFinal{CupdiceLayout::final27, 27, 450.0, 190.0 + 220.0 / 3.0};
constexpr Layout kLegacy{CupdiceLayout::legacy24, 24, 450.0, 185.0 + 220.0 / 3.0};

std::vector<std::vector<double>> read_rows(const fs::path& file) {
  std::ifstream in = open_for_reading(file);
  std::vector<std::vector<double>> rows;
  std::string line;
  std::size_t line_no = 0, columns = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::vector<double> row;
    std::size_t start = 0;
    while (true) {
      const auto comma = line.find(',', start);
      const std::string_view f(line.data() + start, (comma == std::string::npos ? line.size() : comma) - start);
      double v = 0.0;
      const auto r = std::from_chars(f.data(), f.data() + f.size(), v);
      if (f.empty() || r.ec != std::errc() || r.ptr != f.data() + f.size())
        throw InputError(file.string() + ":" + std::to_string(line_no) + ": column " + std::to_string(row.size() + 1) +
                         ": \"" + std::string(f) + "\" is not a number");
      if (!std::isfinite(v))
        throw InputError(file.string() + ":" + std::to_string(line_no) + ": column " + std::to_string(row.size() + 1) +
                         " is not finite");
      row.push_back(v);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (columns == 0) columns = row.size();
    if (columns != 27 && columns != 24)
      throw InputError(file.string() + ":" + std::to_string(line_no) + ": " + std::to_string(columns) +
                       " columns; an original recording has 27 (final layout) or 24 (legacy layout)");
    if (row.size() != columns)
      throw InputError(file.string() + ":" + std::to_string(line_no) + ": " + std::to_string(row.size()) +
                       " columns, expected " + std::to_string(columns) + " as on line 1");
    rows.push_back(std::move(row));
  }
  check_read(in, file);
  if (rows.empty()) throw InputError(file.string() + ": no rows");
  return rows;
}

// Cup pose and dice of an original row, in SI with the cup at its centre of mass.
State pose_from_row(const std::vector<double>& r, const Layout& layout) {
  State s{};
  const double angle = r[2], c = std::cos(angle), sn = std::sin(angle);
  s[si::kCupX] = (r[0] + c * layout.com_x - sn * layout.com_y) / kPxPerMetre;
  s[si::kCupY] = (r[1] + sn * layout.com_x + c * layout.com_y) / kPxPerMetre;
  s[si::kCupAngle] = angle;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    const std::size_t d = si::die(i), col = 3 + 6 * i;
    s[d] = r[col] / kPxPerMetre;
    s[d + 1] = r[col + 1] / kPxPerMetre;
    s[d + 2] = r[col + 2];
    s[d + 3] = r[col + 3] / kPxPerMetre;
    s[d + 4] = r[col + 4] / kPxPerMetre;
    s[d + 5] = r[col + 5];
  }
  return s;
}

void check_start_pose(const fs::path& file, const std::vector<double>& r, const Layout& layout) {
  // At the start the cup hangs at angle pi, so its origin sits at twice its centre of mass.
  // Legacy rows are recorded after the first step, so allow for one step of motion.
  const double tolerance = layout.kind == CupdiceLayout::final27 ? 1.0 : 40.0;
  if (std::abs(r[2] - std::numbers::pi) > tolerance / 200.0 || std::abs(r[0] - 2.0 * layout.com_x) > tolerance ||
      std::abs(r[1] - 2.0 * layout.com_y) > tolerance)
    throw InputError(file.string() + ":1: the cup is at (" + std::to_string(r[0]) + ", " + std::to_string(r[1]) + ", " +
                     std::to_string(r[2]) + "), not the original's start pose (" + std::to_string(2.0 * layout.com_x) +
                     ", " + std::to_string(2.0 * layout.com_y) + ", pi); cannot place the cup's centre of mass");
}

Outcome judge_recording(const std::vector<State>& states, const State& last, const WorldConfig& world) {
  Outcome o = judge_states(states, last, world);
  if (!o.stacked) {
    // Recordings stop while a finished stack may still wobble: let it settle, cup held still.
    const Settled settled = settle(last, world);
    o.stacked = settled.stacked;
    o.stacked_steps = settled.stacked ? 1 : 0;
    o.wall_contact = o.wall_contact || settled.wall_contact;
  }
  return o;
}

// Orders paths so that embedded numbers compare by value (imitate_2 before imitate_10).
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    if (std::isdigit(static_cast<unsigned char>(a[i])) && std::isdigit(static_cast<unsigned char>(b[j]))) {
      std::size_t ie = i, je = j;
      while (ie < a.size() && std::isdigit(static_cast<unsigned char>(a[ie]))) ++ie;
      while (je < b.size() && std::isdigit(static_cast<unsigned char>(b[je]))) ++je;
      const auto na = std::stoull(a.substr(i, ie - i)), nb = std::stoull(b.substr(j, je - j));
      if (na != nb) return na < nb;
      i = ie, j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i, ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

}  // namespace

Episode import_cupdice_file(const fs::path& file, const WorldConfig& world) {
  const auto rows = read_rows(file);
  const Layout& layout = rows.front().size() == 27 ? kFinal : kLegacy;
  check_start_pose(file, rows.front(), layout);
  Episode e;
  e.name = file.stem().string();
  e.origin = "cupdice " + std::string(layout.kind == CupdiceLayout::final27 ? "final" : "legacy") + " " + file.string();
  State last{};
  if (layout.kind == CupdiceLayout::final27) {
    // Row t: the state before the step, except the cup's velocity, which already includes
    // the action (columns 21-23); columns 24-26 are the action, a velocity change.
    for (const auto& r : rows) {
      State s = pose_from_row(r, layout);
      const Action a{r[24] / kPxPerMetre, r[25] / kPxPerMetre, r[26]};
      s[si::kCupVx] = r[21] / kPxPerMetre - a[0];
      s[si::kCupVy] = r[22] / kPxPerMetre - a[1];
      s[si::kCupW] = r[23] - a[2];
      e.states.push_back(s);
      e.actions.push_back(a);
    }
    last = e.states.back();
    last[si::kCupVx] += e.actions.back()[0];
    last[si::kCupVy] += e.actions.back()[1];
    last[si::kCupW] += e.actions.back()[2];
  } else {
    // Row t: the state after step t and the cup velocity commanded in it. The state before
    // action t is row t-1 with the cup moving at the previous command, plus one step of our
    // world's gravity (the legacy game cancelled gravity on the cup); the action is the change
    // to this step's command. The first command (from rest) has no recorded state before it.
    const double dt = world.physics.control_dt;
    for (std::size_t t = 1; t < rows.size(); ++t) {
      const auto &prev = rows[t - 1], &now = rows[t];
      State s = pose_from_row(prev, layout);
      s[si::kCupVx] = prev[21] / kPxPerMetre + world.physics.gravity.x * dt;
      s[si::kCupVy] = prev[22] / kPxPerMetre + world.physics.gravity.y * dt;
      s[si::kCupW] = prev[23];
      const Action a{now[21] / kPxPerMetre - s[si::kCupVx], now[22] / kPxPerMetre - s[si::kCupVy],
                     now[23] - s[si::kCupW]};
      e.states.push_back(s);
      e.actions.push_back(a);
    }
    if (e.states.empty()) throw InputError(file.string() + ": a legacy recording needs at least two rows");
    last = pose_from_row(rows.back(), layout);
    last[si::kCupVx] = rows.back()[21] / kPxPerMetre;
    last[si::kCupVy] = rows.back()[22] / kPxPerMetre;
    last[si::kCupW] = rows.back()[23];
  }
  e.sources.assign(e.states.size(), StepSource::human);
  e.outcome = judge_recording(e.states, last, world);
  // Format v2: the last row is the final state; rewards as DiceEnv::step would give them for the
  // recorded states; a recording ends in success when the judge says so, otherwise it was stopped.
  e.final_state = last;
  const State goal = goal_state(world);
  for (std::size_t t = 0; t < e.states.size(); ++t)
    e.rewards.push_back(step_reward(t + 1 < e.states.size() ? e.states[t + 1] : last, static_cast<int>(t + 1), world, goal));
  e.terminated = e.outcome.realistic_success();
  e.truncated = !e.terminated;
  return e;
}

DemoSet import_cupdice(const fs::path& src, const WorldConfig& world) {
  if (!fs::is_directory(src)) throw InputError(src.string() + ": not a folder");
  std::vector<std::string> files;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(src, ec), end; it != end; it.increment(ec))
    if (it->is_regular_file() && it->path().extension() == ".csv")
      files.push_back(fs::relative(it->path(), src).generic_string());
  if (ec) throw InputError(src.string() + ": cannot list the folder: " + ec.message());
  if (files.empty()) throw InputError(src.string() + ": no *.csv recordings found");
  std::sort(files.begin(), files.end(), natural_less);
  DemoSet set;
  set.world = world;
  set.description = "The paper's human demonstrations (leonidk/cupdice, MIT), converted by dicestack import cupdice";
  set.provenance = "dicestack import cupdice " + src.string() + "; episode i is the i-th file of:";
  for (const auto& f : files) {
    Episode e = import_cupdice_file(src / f, world);
    e.origin = "cupdice " + f;
    set.provenance += " " + f;
    set.episodes.push_back(std::move(e));
  }
  return set;
}

}  // namespace dicestack
