#include <algorithm>
#include <charconv>
#include <cmath>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/interop/interop.hpp>

#include "common.hpp"
#include "h5.hpp"

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace interop;

// Our own export: an HDF5 file whose /data carries the "dicestack" attribute with our marker.
bool is_own_robomimic_file(const fs::path& path) {
  try {
    if (!h5::is_hdf5(path)) return false;
    h5::ReadFile f(path);
    if (!h5::exists(f.root(), "data")) return false;
    const h5::Id data = h5::open_group(f.root(), "data", f.name());
    const auto record = h5::read_attr_string(data.get(), "dicestack", f.name());
    return record && parse_json_text(*record, f.name()).value("format", "") == kRobomimicFormat;
  } catch (const std::exception&) {
    return false;
  }
}

Ownership robomimic_ownership() { return {"dicestack robomimic export (HDF5 with our marker)", is_own_robomimic_file}; }

std::vector<double> column_block(const std::vector<State>& rows, const std::array<std::size_t, 3>& index) {
  std::vector<double> out;
  out.reserve(rows.size() * 3);
  for (const auto& s : rows)
    for (std::size_t k : index) out.push_back(s[k]);
  return out;
}

// demo_<n> -> n; -1 for any other name.
long demo_number(const std::string& name) {
  if (name.rfind("demo_", 0) != 0 || name.size() == 5 || name.size() > 15) return -1;
  long n = 0;
  const auto r = std::from_chars(name.data() + 5, name.data() + name.size(), n);
  if (r.ec != std::errc() || r.ptr != name.data() + name.size() || n < 0) return -1;
  return n;
}

std::string row_col(std::size_t r, std::size_t c) { return "row " + std::to_string(r) + " column " + std::to_string(c); }

// Checks /data's env_args attribute (our gym id, robomimic's gym type, the action limits) and
// takes the world from its env_kwargs.
void read_robomimic_env_args(hid_t data, const std::string& F, WorldConfig& world) {
  const auto env_text = h5::read_attr_string(data, "env_args", F + ": data");
  if (!env_text) throw InputError(F + ": data: attribute env_args is missing");
  const std::string env_where = F + ": data attribute env_args";
  const json env = parse_json_text(*env_text, env_where);
  if (!env.is_object() || !env.contains("env_name") || !env["env_name"].is_string())
    throw InputError(env_where + ": \"env_name\" must be a string");
  if (env["env_name"] != kGymEnvId)
    throw InputError(env_where + ": env_name \"" + env["env_name"].get<std::string>().substr(0, 60) + "\" is not " + kGymEnvId);
  if (!env.contains("type") || env["type"] != kRobomimicGymType)
    throw InputError(env_where + ": \"type\" must be " + std::to_string(kRobomimicGymType) + " (robomimic's gym type)");
  if (env.contains("env_kwargs") && env["env_kwargs"].is_object() && env["env_kwargs"].contains("world"))
    world = world_config_from_json(env["env_kwargs"]["world"].dump(), env_where + " env_kwargs.world");
  const auto& limit = world.action.limit;
  if (env.contains("action_limits")) {
    const json& l = env["action_limits"];
    bool same = l.is_array() && l.size() == kActionDim;
    for (std::size_t k = 0; same && k < kActionDim; ++k) same = l[k].is_number() && l[k].get<double>() == limit[k];
    if (!same) throw InputError(env_where + ": \"action_limits\" must be the world's action.limit, " + json(limit).dump());
  }
}

// The description and provenance from /data's dicestack attribute (our marker), if it has one.
void read_robomimic_set_record(hid_t data, const std::string& F, DemoSet& set) {
  if (const auto record = h5::read_attr_string(data, "dicestack", F + ": data")) {
    const json r = parse_json_text(*record, F + ": data attribute dicestack");
    if (r.value("format", "") != kRobomimicFormat)
      throw InputError(F + ": data attribute dicestack: \"format\" is not " + kRobomimicFormat);
    if (!r.contains("version") || !r["version"].is_number_integer())
      throw InputError(F + ": data attribute dicestack: \"version\" must be an integer");
    if (r["version"].get<std::int64_t>() > kInteropFormatVersion)
      throw InputError(F + ": format version " + std::to_string(r["version"].get<std::int64_t>()) +
                       " is newer than this dicestack reads (" + std::to_string(kInteropFormatVersion) + "); upgrade dicestack");
    set.description = r.value("description", "");
    set.provenance = r.value("provenance", "");
  } else {
    set.description = "imported from robomimic file " + F;
  }
}

// The demo_<n> groups under /data as (n, name), sorted by n; any other member is an error.
std::vector<std::pair<long, std::string>> list_robomimic_demos(hid_t data, const std::string& F) {
  std::vector<std::pair<long, std::string>> demos;
  for (const auto& name : h5::members(data, F + ": data")) {
    const long n = demo_number(name);
    if (n < 0) throw InputError(F + ": data/" + name.substr(0, 60) + ": not a demo_<n> group");
    demos.emplace_back(n, name);
  }
  if (demos.empty()) throw InputError(F + ": data: holds no demo_<n> group");
  std::sort(demos.begin(), demos.end());
  return demos;
}

// Checks a demo's obs/ and next_obs/ against its states; returns the final state next_obs ends with.
State check_robomimic_observations(hid_t demo, const std::string& where, const std::string& path,
                                   const std::vector<State>& states) {
  const std::size_t steps = states.size();
  State final_state{};
  for (const auto& key : observation_keys()) {
    const h5::Array o = read_shaped(demo, std::string("obs/") + key.name, where + "/obs/" + key.name, steps, 3);
    const h5::Array n = read_shaped(demo, std::string("next_obs/") + key.name, where + "/next_obs/" + key.name, steps, 3);
    for (std::size_t t = 0; t < steps; ++t)
      for (std::size_t c = 0; c < 3; ++c) {
        if (o.values[t * 3 + c] != states[t][key.index[c]])
          throw InputError(where + "/obs/" + key.name + ": " + row_col(t, c) + " disagrees with " + path + "/states");
        if (t + 1 < steps && n.values[t * 3 + c] != states[t + 1][key.index[c]])
          throw InputError(where + "/next_obs/" + key.name + ": " + row_col(t, c) + " disagrees with " + path +
                           "/states row " + std::to_string(t + 1));
      }
    for (std::size_t c = 0; c < 3; ++c) final_state[key.index[c]] = n.values[(steps - 1) * 3 + c];
  }
  return final_state;
}

// A demo's actions in world units: the scaled actions times the limits, or our exact
// dicestack/actions where present (checked against the scaled ones).
std::vector<Action> read_robomimic_actions(hid_t demo, const std::string& where, const std::string& path,
                                           const h5::Array& actions, const std::array<double, kActionDim>& limit) {
  const std::size_t steps = actions.dims[0];
  std::vector<Action> out(steps);
  const bool has_raw = h5::exists(demo, "dicestack/actions");
  const h5::Array raw =
      has_raw ? read_shaped(demo, "dicestack/actions", where + "/dicestack/actions", steps, kActionDim) : h5::Array{};
  for (std::size_t t = 0; t < steps; ++t)
    for (std::size_t k = 0; k < kActionDim; ++k) {
      const double v = actions.values[t * kActionDim + k];
      if (v < -1.0 || v > 1.0)
        throw InputError(where + "/actions: " + row_col(t, k) + " is outside [-1, 1] (actions are divided by the action limits)");
      double a = v * limit[k];
      if (has_raw) {
        const double r = raw.values[t * kActionDim + k];
        if (!(std::abs(r / limit[k] - v) <= 1e-12))
          throw InputError(where + "/dicestack/actions: " + row_col(t, k) + " disagrees with " + path + "/actions");
        a = r;
      }
      if (std::abs(a) > limit[k])
        throw InputError(where + "/dicestack/actions: " + row_col(t, k) + " is outside the world's action.limit");
      out[t][k] = a;
    }
  return out;
}

// robosuite's robot0_joint_pos (or, with `rates`, robot0_joint_vel) of an arm at each state:
// each joint's angle is its body's less the body's before it, the cup (the wrist's body) from
// the state.
std::vector<double> joint_rows(const std::vector<State>& states, const std::vector<ArmLinks>& links, bool rates) {
  std::vector<double> out;
  out.reserve(4 * states.size());
  for (std::size_t t = 0; t < states.size(); ++t) {
    const auto joints = arm_joint_angles_of(rates ? links[t].rates : links[t].angles,
                                            states[t][rates ? state_index::kCupW : state_index::kCupAngle]);
    out.insert(out.end(), joints.begin(), joints.end());
  }
  return out;
}

// An arm's readings: robosuite's joint observations (obs/ and next_obs/), the torques its joints
// held as an action of their own (action_dict/joint_torques, N m) and, for an exact round trip,
// our links (dicestack/links: angles then rates; dicestack/final_links).
void write_robomimic_arm(hid_t demo, hid_t obs, hid_t next_obs, hid_t ours, const Episode& e) {
  const hsize_t steps = e.size();
  std::vector<State> next(e.states.begin() + 1, e.states.end());
  next.push_back(*e.final_state);
  std::vector<ArmLinks> next_links(e.links.begin() + 1, e.links.end());
  next_links.push_back(*e.final_links);
  for (const bool rates : {false, true}) {
    const char* key = rates ? "robot0_joint_vel" : "robot0_joint_pos";
    h5::write_f64(obs, key, {steps, 4}, joint_rows(e.states, e.links, rates).data());
    h5::write_f64(next_obs, key, {steps, 4}, joint_rows(next, next_links, rates).data());
  }
  std::vector<double> links;
  for (const auto& l : e.links) {
    links.insert(links.end(), l.angles.begin(), l.angles.end());
    links.insert(links.end(), l.rates.begin(), l.rates.end());
  }
  h5::write_f64(ours, "links", {steps, 6}, links.data());
  std::vector<double> last(e.final_links->angles.begin(), e.final_links->angles.end());
  last.insert(last.end(), e.final_links->rates.begin(), e.final_links->rates.end());
  h5::write_f64(ours, "final_links", {6}, last.data());
  if (e.joint_torques.empty()) return;
  std::vector<double> torques;
  for (const auto& tau : e.joint_torques) torques.insert(torques.end(), tau.begin(), tau.end());
  const h5::Id actions = h5::create_group(demo, "action_dict");
  h5::write_f64(actions.get(), "joint_torques", {steps, 4}, torques.data());
}

// write_robomimic_arm's readings back, where the demo has them.
void read_robomimic_arm(hid_t demo, const std::string& where, Episode& e) {
  const std::size_t steps = e.size();
  if (!h5::exists(demo, "dicestack/links")) {
    if (h5::exists(demo, "action_dict/joint_torques"))
      throw InputError(where + "/action_dict/joint_torques: an arm's joint torques need its links (dicestack/links)");
    return;
  }
  const h5::Array links = read_shaped(demo, "dicestack/links", where + "/dicestack/links", steps, 6);
  const h5::Array last = read_shaped(demo, "dicestack/final_links", where + "/dicestack/final_links", 6, 0);
  h5::Array angles, rates;
  for (std::size_t t = 0; t <= steps; ++t)
    for (std::size_t i = 0; i < 3; ++i) {
      angles.values.push_back(t < steps ? links.values[6 * t + i] : last.values[i]);
      rates.values.push_back(t < steps ? links.values[6 * t + 3 + i] : last.values[3 + i]);
    }
  links_from_rows(angles, rates, e);
  std::vector<State> next(e.states.begin() + 1, e.states.end());
  next.push_back(*e.final_state);
  std::vector<ArmLinks> next_links(e.links.begin() + 1, e.links.end());
  next_links.push_back(*e.final_links);
  for (const char* group : {"obs/", "next_obs/"})
    for (const bool r : {false, true}) {
      const std::string key = std::string(group) + (r ? "robot0_joint_vel" : "robot0_joint_pos");
      if (!h5::exists(demo, key)) continue;
      const h5::Array seen = read_shaped(demo, key, where + "/" + key, steps, 4);
      const bool later = group[0] == 'n';
      const std::vector<double> expected = later ? joint_rows(next, next_links, r) : joint_rows(e.states, e.links, r);
      for (std::size_t k = 0; k < expected.size(); ++k)
        if (!(std::abs(seen.values[k] - expected[k]) <= 1e-9))
          throw InputError(where + "/" + key + ": " + row_col(k / 4, k % 4) + " disagrees with dicestack/links and the states");
    }
  if (!h5::exists(demo, "action_dict/joint_torques")) return;
  const h5::Array torques = read_shaped(demo, "action_dict/joint_torques", where + "/action_dict/joint_torques", steps, 4);
  e.joint_torques.assign(steps, {});
  for (std::size_t t = 0; t < steps; ++t)
    std::copy_n(torques.values.begin() + static_cast<std::ptrdiff_t>(4 * t), 4, e.joint_torques[t].begin());
}

// Reads and checks the group data/<name>, the episode at `index`.
Episode read_robomimic_demo(const h5::ReadFile& f, const std::string& name, std::size_t index, const WorldConfig& world) {
  const std::string& F = f.name();
  const std::string path = "data/" + name;
  const std::string where = F + ": " + path;
  const h5::Id demo = h5::open_group(f.root(), path, where);
  const auto samples = h5::read_attr_int(demo.get(), "num_samples", where);
  if (!samples) throw InputError(where + ": attribute num_samples is missing");
  const h5::Array actions = read_rows(demo.get(), "actions", where + "/actions", kActionDim);
  const std::size_t steps = actions.dims[0];
  if (*samples != static_cast<std::int64_t>(steps))
    throw InputError(where + ": attribute num_samples is " + std::to_string(*samples) + ", but actions has " +
                     std::to_string(steps) + " rows");
  const h5::Array states = read_shaped(demo.get(), "states", where + "/states", steps, kStateDim);
  const h5::Array rewards = read_shaped(demo.get(), "rewards", where + "/rewards", steps, 0);
  const h5::Array dones = read_shaped(demo.get(), "dones", where + "/dones", steps, 0, true);
  for (std::size_t t = 0; t < steps; ++t)
    if (dones.values[t] != 0.0 && dones.values[t] != 1.0)
      throw InputError(where + "/dones: item " + std::to_string(t) + " is neither 0 nor 1");

  Episode e;
  e.states.resize(steps);
  for (std::size_t t = 0; t < steps; ++t)
    std::copy_n(states.values.begin() + static_cast<std::ptrdiff_t>(t * kStateDim), kStateDim, e.states[t].begin());
  e.final_state = check_robomimic_observations(demo.get(), where, path, e.states);
  e.rewards = rewards.values;
  e.actions = read_robomimic_actions(demo.get(), where, path, actions, world.action.limit);
  read_robomimic_arm(demo.get(), where, e);

  read_episode_record(demo.get(), where, index, "dicestack_seed", "robomimic " + F + " " + name, world, e);
  const auto terminated = h5::read_attr_int(demo.get(), "dicestack_terminated", where);
  const auto truncated = h5::read_attr_int(demo.get(), "dicestack_truncated", where);
  e.terminated = terminated ? *terminated != 0 : e.outcome.realistic_success();
  e.truncated = truncated ? *truncated != 0 : !e.terminated;
  check_read_episode(e, where);
  return e;
}

}  // namespace

void export_robomimic(const DemoSet& set, const fs::path& file) {
  validate(set.world);
  require_transitions(set.episodes, file.string());
  require_cup_actions(set.episodes, file.string());
  for (const auto& e : set.episodes) check_episode(e);
  const bool arm = arm_episodes(set.episodes, file.string());
  check_replaceable(file, robomimic_ownership());  // before any work
  const auto& limit = set.world.action.limit;

  h5::MemoryFile f;
  const h5::Id data = h5::create_group(f.root(), "data");
  std::int64_t total = 0;
  std::vector<std::string> train, valid;
  for (std::size_t i = 0; i < set.episodes.size(); ++i) {
    const Episode& e = set.episodes[i];
    const std::string name = "demo_" + std::to_string(i);
    (is_test_episode(i) ? valid : train).push_back(name);
    const h5::Id demo = h5::create_group(data.get(), name);
    const hsize_t steps = e.size();
    total += static_cast<std::int64_t>(steps);

    std::vector<double> scaled, raw, states, rewards = e.rewards;
    for (const auto& a : e.actions)
      for (std::size_t k = 0; k < kActionDim; ++k) {
        scaled.push_back(a[k] / limit[k]);
        raw.push_back(a[k]);
      }
    for (const auto& s : e.states) states.insert(states.end(), s.begin(), s.end());
    std::vector<std::int64_t> dones(steps, 0);
    dones.back() = 1;  // the trajectory ends here (terminated or truncated: see the attributes)
    h5::write_f64(demo.get(), "actions", {steps, kActionDim}, scaled.data());
    h5::write_f64(demo.get(), "states", {steps, kStateDim}, states.data());
    h5::write_f64(demo.get(), "rewards", {steps}, rewards.data());
    h5::write_i64(demo.get(), "dones", dones);

    std::vector<State> next(e.states.begin() + 1, e.states.end());
    next.push_back(*e.final_state);
    const h5::Id obs = h5::create_group(demo.get(), "obs");
    const h5::Id next_obs = h5::create_group(demo.get(), "next_obs");
    for (const auto& key : observation_keys()) {
      h5::write_f64(obs.get(), key.name, {steps, 3}, column_block(e.states, key.index).data());
      h5::write_f64(next_obs.get(), key.name, {steps, 3}, column_block(next, key.index).data());
    }
    // The world-unit actions, so that the round trip is exact (a / limit * limit is not always a).
    const h5::Id ours = h5::create_group(demo.get(), "dicestack");
    h5::write_f64(ours.get(), "actions", {steps, kActionDim}, raw.data());
    if (arm) write_robomimic_arm(demo.get(), obs.get(), next_obs.get(), ours.get(), e);

    h5::attr_i64(demo.get(), "num_samples", static_cast<std::int64_t>(steps));
    h5::attr_string(demo.get(), "dicestack_name", e.name);
    h5::attr_u64(demo.get(), "dicestack_seed", e.seed);
    h5::attr_string(demo.get(), "dicestack_origin", e.origin);
    h5::attr_string(demo.get(), "dicestack_sources", sources_text(e.sources));
    h5::attr_string(demo.get(), "dicestack_outcome", outcome_json(e.outcome).dump());
    h5::attr_i64(demo.get(), "dicestack_terminated", e.terminated);
    h5::attr_i64(demo.get(), "dicestack_truncated", e.truncated);
  }
  const json env_args = {{"env_name", kGymEnvId},
                         {"type", kRobomimicGymType},
                         {"env_kwargs", {{"world", json::parse(to_json(set.world))}}},
                         {"action_limits", limit}};
  h5::attr_i64(data.get(), "total", total);
  h5::attr_string(data.get(), "env_args", env_args.dump());
  h5::attr_string(data.get(), "dicestack", set_record(set, kRobomimicFormat).dump());
  const h5::Id mask = h5::create_group(f.root(), "mask");
  h5::write_fixed_strings(mask.get(), "train", train);
  h5::write_fixed_strings(mask.get(), "valid", valid);

  const std::string bytes = f.image();
  AtomicFile out(file, robomimic_ownership());
  out.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.commit();
}

DemoSet import_robomimic(const fs::path& file) {
  h5::ReadFile f(file);
  const std::string F = f.name();
  const h5::Id data = h5::open_group(f.root(), "data", F + ": data");
  DemoSet set;
  read_robomimic_env_args(data.get(), F, set.world);
  read_robomimic_set_record(data.get(), F, set);
  const auto demos = list_robomimic_demos(data.get(), F);
  std::int64_t total = 0;
  for (std::size_t i = 0; i < demos.size(); ++i) {
    Episode e = read_robomimic_demo(f, demos[i].second, i, set.world);
    total += static_cast<std::int64_t>(e.actions.size());  // num_samples, checked equal to the rows
    set.episodes.push_back(std::move(e));
  }
  if (const auto t = h5::read_attr_int(data.get(), "total", F + ": data"); t && *t != total)
    throw InputError(F + ": data: attribute total is " + std::to_string(*t) + ", but the demos hold " + std::to_string(total) +
                     " samples");
  return set;
}

}  // namespace dicestack
