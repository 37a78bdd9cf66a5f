#include "common.hpp"

#include <charconv>
#include <cstdio>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/datasets/replay.hpp>
#include <dicestack/interop/interop.hpp>
#include <dicestack/version.hpp>

namespace dicestack {

namespace {

constexpr std::array<ObservationKey, 2 + 2 * kDiceCount> kKeys{{
    {"cup_pose", {state_index::kCupX, state_index::kCupY, state_index::kCupAngle}},
    {"cup_vel", {state_index::kCupVx, state_index::kCupVy, state_index::kCupW}},
    {"die0_pose", {state_index::die(0), state_index::die(0) + 1, state_index::die(0) + 2}},
    {"die0_vel", {state_index::die(0) + 3, state_index::die(0) + 4, state_index::die(0) + 5}},
    {"die1_pose", {state_index::die(1), state_index::die(1) + 1, state_index::die(1) + 2}},
    {"die1_vel", {state_index::die(1) + 3, state_index::die(1) + 4, state_index::die(1) + 5}},
    {"die2_pose", {state_index::die(2), state_index::die(2) + 1, state_index::die(2) + 2}},
    {"die2_vel", {state_index::die(2) + 3, state_index::die(2) + 4, state_index::die(2) + 5}},
}};

}  // namespace

std::span<const ObservationKey> observation_keys() { return kKeys; }

void require_transitions(const std::vector<Episode>& episodes, const std::string& where) {
  std::vector<std::string> missing;
  for (const auto& e : episodes)
    if (!e.has_transitions()) missing.push_back(e.name.empty() ? "(unnamed)" : e.name);
  if (missing.empty()) return;
  std::string list;
  for (std::size_t i = 0; i < missing.size() && i < 10; ++i) list += (i ? ", " : "") + missing[i];
  if (missing.size() > 10) list += " and " + std::to_string(missing.size() - 10) + " more";
  throw InputError(where + ": " + std::to_string(missing.size()) + " of " + std::to_string(episodes.size()) +
                   " episodes have no final state, rewards or end flags (format v1, and replaying them does not "
                   "reproduce their recorded states): " + list);
}

namespace interop {
namespace {

std::string shape_text(const std::vector<hsize_t>& d) {
  std::string s = "(";
  for (std::size_t i = 0; i < d.size(); ++i) s += (i ? ", " : "") + std::to_string(d[i]);
  return s + (d.size() == 1 ? ",)" : ")");
}

}  // namespace

h5::Array read_shaped(hid_t loc, const std::string& name, const std::string& where, std::size_t rows, std::size_t cols,
                      bool integral) {
  h5::Array a = h5::read_numbers(loc, name, where, integral);
  const std::vector<hsize_t> want = cols ? std::vector<hsize_t>{rows, cols} : std::vector<hsize_t>{rows};
  if (a.dims != want) throw InputError(where + ": shape " + shape_text(a.dims) + ", expected " + shape_text(want));
  return a;
}

h5::Array read_rows(hid_t loc, const std::string& name, const std::string& where, std::size_t cols) {
  h5::Array a = h5::read_numbers(loc, name, where);
  if (a.dims.size() != 2 || a.dims[1] != cols || a.dims[0] == 0)
    throw InputError(where + ": shape " + shape_text(a.dims) + ", expected (T, " + std::to_string(cols) + ") with T >= 1");
  return a;
}


std::string sources_text(const std::vector<StepSource>& sources) {
  std::string out;
  for (std::size_t i = 0; i < sources.size();) {
    std::size_t j = i;
    while (j < sources.size() && sources[j] == sources[i]) ++j;
    out += (out.empty() ? "" : ",") + std::string(to_string(sources[i])) + ":" + std::to_string(j - i);
    i = j;
  }
  return out;
}

std::vector<StepSource> sources_from_text(const std::string& text, std::size_t steps, const std::string& where) {
  std::vector<StepSource> out;
  std::size_t start = 0;
  while (start < text.size()) {
    const auto comma = text.find(',', start);
    const std::string run = text.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    const auto colon = run.find(':');
    if (colon == std::string::npos) throw InputError(where + ": \"" + run.substr(0, 40) + "\" is not source:count");
    StepSource s;
    try {
      s = step_source_from(run.substr(0, colon));
    } catch (const InputError& e) {
      throw InputError(where + ": " + e.what());
    }
    std::size_t n = 0;
    const char* b = run.data() + colon + 1;
    const char* e = run.data() + run.size();
    const auto r = std::from_chars(b, e, n);
    if (r.ec != std::errc() || r.ptr != e || n == 0 || n > steps - out.size())
      throw InputError(where + ": run \"" + run.substr(0, 40) + "\" does not fit " + std::to_string(steps) + " steps");
    out.insert(out.end(), n, s);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  if (out.size() != steps)
    throw InputError(where + ": gives " + std::to_string(out.size()) + " sources for " + std::to_string(steps) + " steps");
  return out;
}

nlohmann::json outcome_json(const Outcome& o) {
  return {{"steps", o.steps}, {"dice_in_cup", o.dice_in_cup}, {"stacked", o.stacked}, {"wall_contact", o.wall_contact}};
}

Outcome outcome_from_json(const nlohmann::json& j, const std::string& where) {
  Outcome o;
  auto integer = [&](const char* key, int lo, int hi) {
    if (!j.is_object() || !j.contains(key) || !j[key].is_number_integer() || j[key].get<std::int64_t>() < lo ||
        j[key].get<std::int64_t>() > hi)
      throw InputError(where + ": \"" + key + "\" must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(j[key].get<std::int64_t>());
  };
  auto flag = [&](const char* key) {
    if (!j.contains(key) || !j[key].is_boolean()) throw InputError(where + ": \"" + key + "\" must be true or false");
    return j[key].get<bool>();
  };
  o.steps = integer("steps", 0, 1 << 30);
  o.dice_in_cup = integer("dice_in_cup", 0, static_cast<int>(kDiceCount));
  o.stacked = flag("stacked");
  o.wall_contact = flag("wall_contact");
  o.stacked_steps = o.stacked ? 1 : 0;  // as read_demo_set reads meta.json
  o.dice_in_cup_now = o.dice_in_cup;
  return o;
}

void read_episode_record(hid_t group, const std::string& where, std::size_t index, const char* seed_attr,
                         const std::string& default_origin, const WorldConfig& world, Episode& e) {
  char fallback[32];
  std::snprintf(fallback, sizeof fallback, "episode_%04zu", index);
  e.name = h5::read_attr_string(group, "dicestack_name", where).value_or(fallback);
  e.seed = h5::read_attr_u64(group, seed_attr, where).value_or(0);
  e.origin = h5::read_attr_string(group, "dicestack_origin", where).value_or(default_origin);
  const std::size_t steps = e.states.size();
  const auto sources = h5::read_attr_string(group, "dicestack_sources", where);
  e.sources = sources ? sources_from_text(*sources, steps, where + " attribute dicestack_sources")
                      : std::vector<StepSource>(steps, StepSource::policy);
  if (const auto outcome = h5::read_attr_string(group, "dicestack_outcome", where)) {
    const std::string what = where + " attribute dicestack_outcome";
    e.outcome = outcome_from_json(parse_json_text(*outcome, what), what);
  } else {
    e.outcome = judge_states(e.states, *e.final_state, world);
    e.outcome.stacked_steps = e.outcome.stacked ? 1 : 0;  // as outcome_from_json and meta.json
    e.outcome.dice_in_cup_now = e.outcome.dice_in_cup;
  }
}

void check_read_episode(const Episode& e, const std::string& where) {
  try {
    check_episode(e);
  } catch (const InputError& err) {
    throw InputError(where + ": " + err.what());
  }
}

nlohmann::json parse_json_text(const std::string& text, const std::string& where) {
  try {
    return parse_json_limited<nlohmann::json>(text, where);
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where + ": not valid JSON: " + e.what());
  }
}

nlohmann::json set_record(const DemoSet& set, const char* format) {
  return {{"format", format},
          {"version", kInteropFormatVersion},
          {"dicestack_version", DICESTACK_VERSION},
          {"demo_format_version", kDemoFormatVersion},
          {"description", set.description},
          {"provenance", set.provenance}};
}

void require_cup_actions(const std::vector<Episode>& episodes, const std::string& where) {
  for (const auto& e : episodes)
    if (!e.actions.empty() && e.actions.front().kind() != ActionKind::cup)
      throw InputError(where + ": episode " + (e.name.empty() ? std::string("(unnamed)") : e.name) +
                       " acts in joint torques; the export carries the cup's actions (dvx, dvy, dw)");
}

bool arm_episodes(const std::vector<Episode>& episodes, const std::string& where) {
  std::vector<std::string> without;
  std::size_t arm = 0;
  for (const auto& e : episodes) {
    arm += !e.links.empty();
    if (e.links.empty() || !e.final_links) without.push_back(e.name.empty() ? "(unnamed)" : e.name);
  }
  if (arm == 0) return false;
  if (without.empty()) return true;
  std::string list;
  for (std::size_t i = 0; i < without.size() && i < 10; ++i) list += (i ? ", " : "") + without[i];
  if (without.size() > 10) list += " and " + std::to_string(without.size() - 10) + " more";
  throw InputError(where + ": " + std::to_string(without.size()) + " of " + std::to_string(episodes.size()) +
                   " episodes lack the arm's links or its links after the last action, which the others have: " + list);
}

std::vector<double> link_rows(const Episode& e, bool rates) {
  std::vector<double> out;
  out.reserve(3 * (e.links.size() + 1));
  for (const auto& l : e.links) out.insert(out.end(), (rates ? l.rates : l.angles).begin(), (rates ? l.rates : l.angles).end());
  const auto& last = rates ? e.final_links->rates : e.final_links->angles;
  out.insert(out.end(), last.begin(), last.end());
  return out;
}

void links_from_rows(const h5::Array& angles, const h5::Array& rates, Episode& e) {
  const std::size_t rows = angles.values.size() / 3;
  e.links.assign(rows - 1, ArmLinks{});
  for (std::size_t t = 0; t < rows; ++t) {
    ArmLinks& l = t + 1 < rows ? e.links[t] : e.final_links.emplace();
    std::copy_n(angles.values.begin() + static_cast<std::ptrdiff_t>(3 * t), 3, l.angles.begin());
    std::copy_n(rates.values.begin() + static_cast<std::ptrdiff_t>(3 * t), 3, l.rates.begin());
  }
}

}  // namespace interop
}  // namespace dicestack
