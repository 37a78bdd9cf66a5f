#include <dicestack/datasets/demo_set.hpp>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iomanip>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <type_traits>
#include <utility>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/core/read_file.hpp>
#include <dicestack/version.hpp>

#include "episode_csv.hpp"

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Whether an episode's entry holds the joint torques' draws (draw_to_json), which version 5 adds.
bool holds_torque_draws(const json& entry) {
  if (!entry.contains("perturbation") || !entry["perturbation"].is_object()) return false;
  const json& p = entry["perturbation"];
  return p.contains("joint_torque_bias") || p.contains("joint_torque_noise_std");
}

std::string episode_file_name(std::size_t index) {
  std::string digits = std::to_string(index);
  if (digits.size() < 4) digits.insert(0, 4 - digits.size(), '0');
  return "episode_" + digits + ".csv";
}

json outcome_json(const Outcome& o) {
  return {{"steps", o.steps},
          {"dice_in_cup", o.dice_in_cup},
          {"stacked", o.stacked},
          {"wall_contact", o.wall_contact},
          {"realistic_success", o.realistic_success()}};
}

json episode_entry(const Episode& e, const std::string& file) {
  std::set<std::string_view> sources;
  for (auto s : e.sources) sources.insert(to_string(s));
  json entry{{"file", file},
             {"seed", e.seed},
             {"steps", e.size()},
             {"origin", e.origin},
             {"sources", std::vector<std::string>(sources.begin(), sources.end())},
             {"outcome", outcome_json(e.outcome)},
             {"final_state", e.final_state ? json(*e.final_state) : json(nullptr)},
             {"terminated", e.terminated},
             {"truncated", e.truncated}};
  if (!e.perturbation.empty()) entry["perturbation"] = json::parse(e.perturbation);
  // Only an arm's episode has the key (version 4), so other sets keep their bytes.
  if (!e.links.empty())
    entry["final_links"] = e.final_links ? json{{"angles", e.final_links->angles}, {"rates", e.final_links->rates}} : json(nullptr);
  return entry;
}

// An arm's readings belong to an arm's world.
void check_links_world(const Episode& e, const WorldConfig& world, const std::string& where) {
  if (!e.links.empty() && world.embodiment != Embodiment::arm)
    throw InputError(where + ": holds an arm's link readings, but the set's world has no arm (\"embodiment\": \"cup\")");
}

// meta.json of `set` (its episodes not read) with these episode entries.
json meta_with_entries(const DemoSet& set, json episodes) {
  const bool perturbed = std::any_of(episodes.begin(), episodes.end(), [](const json& e) { return e.contains("perturbation"); });
  const bool arm = std::any_of(episodes.begin(), episodes.end(), [](const json& e) { return e.contains("final_links"); });
  const bool torque_draws = std::any_of(episodes.begin(), episodes.end(), [](const json& e) { return holds_torque_draws(e); });
  // Version 3 only adds the perturbation, version 4 an arm's readings, version 5 the draws of a
  // perturbed episode in joint torques: a set without them is written as the version before.
  json units{{"length", "m"},
             {"angle", "rad"},
             {"time", "s"},
             {"control_dt", set.world.physics.control_dt},
             {"state", "before the step's action; cup x, y at its centre of mass"},
             {"action", "velocity change of the cup applied at the start of the step: dvx, dvy (m/s), dw (rad/s)"},
             {"reward", "DiceEnv::step's reward for arriving at the next state (empty: unknown)"},
             {"final_state", "the state after the last action (null: unknown)"}};
  if (arm) {
    units["links"] = "each arm link's absolute angle (rad) and rate (rad/s) before the step's action, shoulder link first";
    units["joint_torques"] = "the torques the four joints held on average over the step, N m, shoulder first (empty: unknown)";
    units["final_links"] = "the links after the last action (null: unknown)";
  }
  return {{"format", kDemoFormat},
          {"version", torque_draws ? 5 : arm ? 4 : perturbed ? 3 : 2},
          {"dicestack_version", DICESTACK_VERSION},
          {"description", set.description},
          {"provenance", set.provenance},
          {"units", std::move(units)},
          {"world", json::parse(to_json(set.world))},
          {"episodes", std::move(episodes)}};
}

json meta_json(const DemoSet& set, const std::vector<std::string>& files) {
  json episodes = json::array();
  for (std::size_t i = 0; i < set.episodes.size(); ++i) episodes.push_back(episode_entry(set.episodes[i], files[i]));
  return meta_with_entries(set, std::move(episodes));
}

[[noreturn]] void meta_error(const fs::path& meta, const std::string& what) { throw InputError(meta.string() + ": " + what); }

template <class T>
T meta_field(const json& j, const char* key, const fs::path& meta, const char* expected) {
  if (!j.contains(key)) meta_error(meta, std::string("missing \"") + key + "\"");
  const json& v = j.at(key);
  auto refuse = [&] {
    meta_error(meta, std::string("\"") + key + "\" must be " + expected + ", got " + v.dump().substr(0, 40));
  };
  // Integers are never narrowed: 1.9, -1 or 4294967297 for an int are refused, not read as 1.
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    if (!v.is_number_integer()) refuse();
    if (v.is_number_unsigned()) {
      if (v.get<std::uint64_t>() > static_cast<std::uint64_t>(std::numeric_limits<T>::max())) refuse();
    } else if (std::is_unsigned_v<T> || v.get<std::int64_t>() < static_cast<std::int64_t>(std::numeric_limits<T>::min())) {
      refuse();
    }
  }
  try {
    return v.get<T>();
  } catch (const json::exception&) {
    refuse();
  }
  return T{};
}

// An optional text field: absent is "", anything but a string is refused.
std::string optional_text(const json& j, const char* key, const fs::path& meta) {
  return j.contains(key) ? meta_field<std::string>(j, key, meta, "a string") : std::string();
}

Outcome outcome_from(const json& j, const fs::path& meta, const std::string& file) {
  Outcome o;
  try {
    o.steps = meta_field<int>(j, "steps", meta, "an integer");
    o.dice_in_cup = meta_field<int>(j, "dice_in_cup", meta, "an integer in [0, 3]");
    if (o.steps < 0 || o.dice_in_cup < 0 || o.dice_in_cup > static_cast<int>(kDiceCount))
      meta_error(meta, "outcome of " + file + " has steps " + std::to_string(o.steps) + " and dice_in_cup " +
                           std::to_string(o.dice_in_cup) + "; expected steps >= 0 and dice_in_cup in [0, 3]");
    o.stacked = meta_field<bool>(j, "stacked", meta, "true or false");
    o.wall_contact = meta_field<bool>(j, "wall_contact", meta, "true or false");
  } catch (const json::exception& e) {
    meta_error(meta, "outcome of " + file + " is malformed: " + e.what());
  }
  o.stacked_steps = o.stacked ? 1 : 0;
  o.dice_in_cup_now = o.dice_in_cup;
  return o;
}

// Version 2's per-episode additions: "final_state" (null or 24 finite numbers), "terminated",
// "truncated".
void transitions_from(const json& entry, const fs::path& meta, DemoMetaEntry& e) {
  if (!entry.contains("final_state")) meta_error(meta, "missing the final_state of " + e.file + " (null when unknown)");
  const json& f = entry["final_state"];
  if (!f.is_null()) {
    if (!f.is_array() || f.size() != kStateDim)
      meta_error(meta, "\"final_state\" of " + e.file + " must be null or a list of " + std::to_string(kStateDim) + " numbers");
    State s{};
    for (std::size_t k = 0; k < kStateDim; ++k) {
      if (!f[k].is_number()) meta_error(meta, "\"final_state\" of " + e.file + ": item " + std::to_string(k) + " is not a number");
      s[k] = f[k].get<double>();
      if (!std::isfinite(s[k])) meta_error(meta, "\"final_state\" of " + e.file + ": item " + std::to_string(k) + " is not finite");
    }
    e.final_state = s;
  }
  e.terminated = meta_field<bool>(entry, "terminated", meta, "true or false");
  e.truncated = meta_field<bool>(entry, "truncated", meta, "true or false");
  if (e.terminated && e.truncated) meta_error(meta, e.file + " is both terminated and truncated");
  if (!e.final_state && (e.terminated || e.truncated))
    meta_error(meta, e.file + " has no final state, so terminated and truncated must be false (unknown)");
}

// Version 4's "final_links" of an arm's episode: null (unknown) or {"angles": [3], "rates": [3]}.
void final_links_from(const json& f, const fs::path& meta, DemoMetaEntry& e) {
  e.arm = true;
  if (f.is_null()) return;
  const std::string what = "\"final_links\" of " + e.file;
  if (!f.is_object() || !f.contains("angles") || !f.contains("rates"))
    meta_error(meta, what + " must be null or an object with \"angles\" and \"rates\" (3 numbers each)");
  ArmLinks l;
  for (const auto& [key, out] : {std::pair<const char*, std::array<double, 3>*>{"angles", &l.angles}, {"rates", &l.rates}}) {
    const json& v = f[key];
    if (!v.is_array() || v.size() != 3) meta_error(meta, what + ": \"" + key + "\" must be a list of 3 numbers");
    for (std::size_t i = 0; i < 3; ++i) {
      if (!v[i].is_number() || !std::isfinite(v[i].get<double>()))
        meta_error(meta, what + ": \"" + key + "\" item " + std::to_string(i) + " is not a finite number");
      (*out)[i] = v[i].get<double>();
    }
  }
  e.final_links = l;
}

ActionKind actions_of(const Episode& e) { return e.actions.empty() ? ActionKind::cup : e.actions.front().kind(); }

// A set holds one kind of action: every episode the cup's, or every episode an arm's joint
// torques. `first` names the set's first episode and its kind.
void check_same_actions(const std::pair<std::string, ActionKind>& first, const Episode& other, const std::string& where) {
  if (first.second != actions_of(other))
    throw InputError(where + ": " + first.first + " acts in " + std::string(action_kind_name(first.second)) + " actions and " +
                     other.name + " in " + std::string(action_kind_name(actions_of(other))) + " ones; a set holds one kind");
}

// A cup action beyond the limits is no action the world takes; joint torques beyond theirs are
// clipped when they run (a teacher's label may ask for more than the joints give).
void check_action_limits(const Episode& e, const WorldConfig& world, const fs::path& path) {
  for (std::size_t t = 0; t < e.size(); ++t)
    for (std::size_t k = 0; k < kActionDim && e.actions[t].kind() == ActionKind::cup; ++k)
      if (std::abs(e.actions[t][k]) > world.action.limit[k])
        throw InputError(path.string() + ":" + std::to_string(t + 2) + ": column \"" + std::string(action_names()[k]) + "\" = " +
                         episode_csv::number_text(e.actions[t][k]) + " is outside [-" +
                         episode_csv::number_text(world.action.limit[k]) + ", " + episode_csv::number_text(world.action.limit[k]) +
                         "] (the world's action.limit)");
}

// The episode file `path` that meta.json's `entry` lists, read and checked against the entry
// (its version, the arm's readings, the transitions, the step count) and the world.
Episode read_listed_episode(const fs::path& path, const fs::path& meta_path, int meta_version, DemoMetaEntry& entry,
                            const WorldConfig& world) {
  int csv_version = 0;
  Episode e = episode_csv::parse(read_file(path), path.string(), path.stem().string(), csv_version);
  // A version-2 set may hold version-1 files (appended to an old set): episodes without transitions.
  if (csv_version > meta_version)
    throw InputError(path.string() + ":1: the header is format version " + std::to_string(csv_version) + "'s (" +
                     (csv_version >= 4 ? "with the arm's links and joint torques" : "with reward") + "), but meta.json says version " +
                     std::to_string(meta_version));
  check_links_world(e, world, path.string());
  if (entry.arm != !e.links.empty())
    meta_error(meta_path, entry.file + (entry.arm ? " has \"final_links\", but its file holds no arm links"
                                                  : " holds an arm's links, but its entry has no \"final_links\" (null when unknown)"));
  if (entry.final_links && !entry.final_state)
    meta_error(meta_path, entry.file + " has final links but no final state; they are known together");
  if (entry.final_state && e.rewards.empty())
    throw InputError(path.string() + ": meta.json gives a final state, so every row needs a reward");
  if (!entry.final_state && !e.rewards.empty())
    throw InputError(path.string() + ": has rewards, but meta.json gives no final state (they are known together)");
  if (entry.steps != e.size())
    meta_error(meta_path, "says " + entry.file + " has " + std::to_string(entry.steps) + " steps; the file has " +
                              std::to_string(e.size()));
  e.final_state = entry.final_state;
  e.terminated = entry.terminated;
  e.truncated = entry.truncated;
  e.seed = entry.seed;
  e.origin = std::move(entry.origin);
  e.perturbation = std::move(entry.perturbation);
  e.final_links = entry.final_links;
  e.outcome = entry.outcome;
  check_action_limits(e, world, path);
  return e;
}

Ownership meta_ownership() { return Ownership::json_object("dicestack demonstration meta.json", kDemoFormat); }

// Our scratch files and folders: ".<name>.tmp-<digits>-..." or ".<name>.old-<digits>-...".
bool is_scratch_name(const std::string& name) {
  if (name.empty() || name[0] != '.') return false;
  for (const char* tag : {".tmp-", ".old-"}) {
    const auto at = name.rfind(tag);
    if (at != std::string::npos && at > 1 && at + 5 < name.size() && std::isdigit(static_cast<unsigned char>(name[at + 5])))
      return true;
  }
  return false;
}

}  // namespace

DemoMeta parse_demo_meta(std::string_view text, const fs::path& meta_path) {
  json meta;
  try {
    meta = parse_json_limited<json>(text, meta_path.string());
  } catch (const json::exception& e) {
    meta_error(meta_path, std::string("not valid JSON: ") + e.what());
  }
  if (!meta.is_object()) meta_error(meta_path, "must be a JSON object");
  const auto format = meta_field<std::string>(meta, "format", meta_path, "a string");
  if (format != kDemoFormat) meta_error(meta_path, "format \"" + format + "\" is not " + kDemoFormat);
  const int version = meta_field<int>(meta, "version", meta_path, "an integer");
  if (version > kDemoFormatVersion)
    meta_error(meta_path, "format version " + std::to_string(version) + " is newer than this dicestack reads (" +
                              std::to_string(kDemoFormatVersion) + "); upgrade dicestack");
  if (version < 1) meta_error(meta_path, "format version " + std::to_string(version) + " is not valid");
  if (!meta.contains("world")) meta_error(meta_path, "missing \"world\"");

  DemoMeta out;
  out.version = version;
  out.world = world_config_from_json(meta["world"].dump(), meta_path.string() + " \"world\"");
  out.description = optional_text(meta, "description", meta_path);
  out.provenance = optional_text(meta, "provenance", meta_path);
  if (!meta.contains("episodes") || !meta["episodes"].is_array()) meta_error(meta_path, "\"episodes\" must be a list");

  std::set<std::string> listed;
  for (const auto& entry : meta["episodes"]) {
    DemoMetaEntry e;
    e.file = meta_field<std::string>(entry, "file", meta_path, "a string");
    if (e.file.empty() || e.file.find_first_of("/\\") != std::string::npos || e.file == "." || e.file == "..")
      meta_error(meta_path, "\"file\" must name a file inside the folder, got \"" + e.file.substr(0, 60) + "\"");
    if (!listed.insert(e.file).second) meta_error(meta_path, "lists " + e.file + " twice");
    e.seed = meta_field<std::uint64_t>(entry, "seed", meta_path, "an unsigned integer");
    e.origin = optional_text(entry, "origin", meta_path);
    e.steps = meta_field<std::size_t>(entry, "steps", meta_path, "an unsigned integer");
    if (!entry.contains("outcome")) meta_error(meta_path, "missing the outcome of " + e.file);
    e.outcome = outcome_from(entry["outcome"], meta_path, e.file);
    if (version >= 2) transitions_from(entry, meta_path, e);
    if (version >= 3 && entry.contains("perturbation")) {
      if (!entry["perturbation"].is_object())
        meta_error(meta_path, "\"perturbation\" of " + e.file + " must be an object (the values its world drew)");
      if (version < 5 && holds_torque_draws(entry))
        meta_error(meta_path, "\"perturbation\" of " + e.file + " has the joint torques' bias or noise, which format version " +
                                  std::to_string(version) + " does not have (version 5 added them)");
      e.perturbation = entry["perturbation"].dump();
    }
    if (version >= 4 && entry.contains("final_links")) final_links_from(entry["final_links"], meta_path, e);
    out.episodes.push_back(std::move(e));
  }
  return out;
}

DemoSet read_demo_set(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string() + ": not a folder of demonstrations");
  const fs::path meta_path = dir / "meta.json";
  // Only a file that is not there is "missing"; any other failure is read_file's to explain.
  auto absent = [&](const fs::path& p) { return fs::status(p, ec).type() == fs::file_type::not_found; };
  if (absent(meta_path)) meta_error(meta_path, "missing; not a dicestack demonstration folder");
  DemoMeta meta = parse_demo_meta(read_file(meta_path), meta_path);

  DemoSet set;
  set.world = meta.world;
  set.description = std::move(meta.description);
  set.provenance = std::move(meta.provenance);
  std::set<std::string> listed;
  for (auto& entry : meta.episodes) {
    listed.insert(entry.file);
    if (absent(dir / entry.file)) meta_error(meta_path, "lists " + entry.file + ", which does not exist");
    set.episodes.push_back(read_listed_episode(dir / entry.file, meta_path, meta.version, entry, set.world));
    const Episode& first = set.episodes.front();
    check_same_actions({first.name, actions_of(first)}, set.episodes.back(), dir.string());
  }
  for (fs::directory_iterator it(dir, ec), end; it != end; it.increment(ec)) {
    const auto name = it->path().filename().string();
    if (it->path().extension() == ".csv" && !listed.contains(name))
      throw InputError(it->path().string() + ": not listed in meta.json");
  }
  if (ec) throw InputError(dir.string() + ": cannot list the folder: " + ec.message());
  std::sort(set.episodes.begin(), set.episodes.end(), [](const Episode& a, const Episode& b) { return a.name < b.name; });
  return set;
}

bool is_own_demo_set(const fs::path& dir, std::string* why) {
  auto no = [&](std::string reason) {
    if (why) *why = std::move(reason);
    return false;
  };
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(dir, ec))) return no("it is not a folder");
  const fs::path meta_path = dir / "meta.json";
  json meta;
  if (fs::is_regular_file(fs::symlink_status(meta_path, ec))) {
    std::ifstream in(meta_path, std::ios::binary);
    try {
      meta = parse_json_limited<json>(in, meta_path.string());
    } catch (const std::exception&) {
      meta = json();
    }
  }
  std::set<std::string> listed;
  const bool meta_ok = meta.is_object() && meta.value("format", json()) == json(kDemoFormat) && meta.contains("episodes") &&
                       meta["episodes"].is_array();
  if (meta_ok)
    for (const auto& entry : meta["episodes"])
      if (entry.is_object() && entry.contains("file") && entry["file"].is_string()) listed.insert(entry["file"].get<std::string>());
  const Ownership sidecar = Ownership::json_object("dicestack baseline summary", kBaselineFormat);
  std::vector<std::string> foreign;
  std::size_t summaries = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const bool file = it->is_regular_file(ec) && !it->is_symlink(ec);
    if (meta_ok && file && (name == "meta.json" || listed.contains(name))) continue;
    if (file && name != "meta.json" && it->path().extension() == ".json" && sidecar.recognises(it->path())) {
      ++summaries;
      continue;
    }
    if (is_scratch_name(name)) continue;
    foreign.push_back(name == "meta.json" ? std::string("a meta.json that is not ours") : name + (it->is_directory(ec) ? "/" : ""));
  }
  if (ec) return no("it cannot be listed: " + ec.message());
  if (!foreign.empty()) {
    std::sort(foreign.begin(), foreign.end());
    return no("it holds " + foreign.front() + (foreign.size() > 1 ? " and " + std::to_string(foreign.size() - 1) + " more" : ""));
  }
  // Only baseline summaries and no meta.json: what rrt wrote when it found no path, before its
  // folder always held a set.
  if (!meta_ok && summaries == 0) return no("it has no dicestack meta.json");
  return true;
}

void check_demo_set_replaceable(const fs::path& dir) {
  std::error_code ec;
  const auto st = fs::symlink_status(dir, ec);
  if (ec || st.type() == fs::file_type::not_found) return;
  if (st.type() == fs::file_type::directory && fs::is_empty(dir, ec) && !ec) return;
  std::string why;
  if (is_own_demo_set(dir, &why)) return;
  throw InputError(dir.string() + ": exists and is not a dicestack demonstration set (" + why +
                   "); refusing to replace it: choose another --out or remove it yourself");
}

void write_demo_set(const DemoSet& set, const fs::path& dir) { write_demo_set(set, dir, {}); }

void write_demo_set(const DemoSet& set, const fs::path& dir, const std::map<std::string, std::string>& sidecars) {
  for (const auto& [name, bytes] : sidecars)
    if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos || name == "meta.json" ||
        fs::path(name).extension() == ".csv")
      throw InputError(dir.string() + ": \"" + name + "\" cannot be written beside a demonstration set");
  validate(set.world);
  std::vector<std::string> files;
  for (std::size_t i = 0; i < set.episodes.size(); ++i) {
    check_episode(set.episodes[i]);
    check_links_world(set.episodes[i], set.world, dir.string() + ": episode " + std::to_string(i));
    check_same_actions({set.episodes[0].name, actions_of(set.episodes[0])}, set.episodes[i], dir.string());
    files.push_back(episode_file_name(i));
  }
  const auto ours = [](const fs::path& p) { return is_own_demo_set(p); };
  replace_folder(dir, ours, check_demo_set_replaceable, [&](const fs::path& tmp) {
    for (std::size_t i = 0; i < set.episodes.size(); ++i) episode_csv::write(set.episodes[i], tmp / files[i], AtomicFile::Leftovers::skip);
    AtomicFile meta(tmp / "meta.json", meta_ownership());
    meta.stream() << meta_json(set, files).dump(2) << '\n';
    meta.commit();
    for (const auto& [name, bytes] : sidecars) {
      AtomicFile f(tmp / name, Ownership::unchecked("sidecar of a demonstration set"), AtomicFile::Leftovers::skip);
      f.stream() << bytes;
      f.commit();
    }
  });
}

std::size_t write_demo_set_streaming(const DemoSet& header, const fs::path& dir,
                                     const std::function<void(const EpisodeSink&)>& produce) {
  validate(header.world);
  std::size_t written = 0;
  const auto ours = [](const fs::path& p) { return is_own_demo_set(p); };
  replace_folder(dir, ours, check_demo_set_replaceable, [&](const fs::path& tmp) {
    json episodes = json::array();
    std::pair<std::string, ActionKind> first;
    produce([&](const Episode& e) {
      check_episode(e);
      check_links_world(e, header.world, dir.string() + ": episode " + std::to_string(written));
      if (written == 0) first = {e.name, actions_of(e)};
      check_same_actions(first, e, dir.string());
      const std::string file = episode_file_name(written);
      episode_csv::write(e, tmp / file, AtomicFile::Leftovers::skip);
      episodes.push_back(episode_entry(e, file));
      ++written;
    });
    AtomicFile meta(tmp / "meta.json", meta_ownership());
    meta.stream() << std::setw(2) << meta_with_entries(header, std::move(episodes)) << '\n';  // dump(2), no copy as text
    meta.commit();
  });
  return written;
}

std::vector<std::string> append_to_demo_set(const fs::path& dir, std::vector<Episode> episodes,
                                            const WorldConfig& world, const std::string& description) {
  DemoSet set;
  if (fs::exists(dir / "meta.json")) {
    set = read_demo_set(dir);
  } else {
    check_demo_set_replaceable(dir);
    set.world = world;
    set.description = description;
    fs::create_directories(dir);
  }
  std::vector<std::string> files, added;
  for (std::size_t i = 0; i < set.episodes.size(); ++i) files.push_back(set.episodes[i].name + ".csv");
  std::size_t next = set.episodes.size();
  // Every episode is checked before any file is written: a refused one leaves the set as it was.
  for (const auto& e : episodes) {
    check_episode(e);
    check_links_world(e, set.world, dir.string());
    const Episode& first = set.episodes.empty() ? episodes.front() : set.episodes.front();
    check_same_actions({first.name, actions_of(first)}, e, dir.string());
  }
  for (auto& e : episodes) {
    std::string file;
    do file = episode_file_name(next++);
    while (fs::exists(dir / file));
    episode_csv::write(e, dir / file, AtomicFile::Leftovers::clean);
    e.name = fs::path(file).stem().string();
    added.push_back(e.name);
    files.push_back(file);
    set.episodes.push_back(std::move(e));
  }
  AtomicFile meta(dir / "meta.json", meta_ownership());
  meta.stream() << meta_json(set, files).dump(2) << '\n';
  meta.commit();
  return added;
}

}  // namespace dicestack
