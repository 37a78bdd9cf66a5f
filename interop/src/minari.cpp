#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/read_file.hpp>
#include <dicestack/interop/interop.hpp>

#include "common.hpp"
#include "h5.hpp"

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using namespace interop;

constexpr const char* kMainFile = "main_data.hdf5";  // Minari's _MAIN_FILE_NAME
constexpr const char* kMetadataFile = "metadata.json";  // Minari's METADATA_FILE_NAME

// A number as Python's json.dumps writes a float (Infinity for inf; shortest round-trip digits).
std::string py_number(double v) {
  if (std::isinf(v)) return v > 0 ? "Infinity" : "-Infinity";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

// Minari's serialize_space for a float64 Box, as the JSON text it stores inside metadata.json.
template <std::size_t N>
std::string box_text(const Box<N>& box) {
  std::string low, high;
  for (std::size_t i = 0; i < N; ++i) {
    low += (i ? ", " : "") + py_number(box.low[i]);
    high += (i ? ", " : "") + py_number(box.high[i]);
  }
  return "{\"type\": \"Box\", \"dtype\": \"float64\", \"shape\": [" + std::to_string(N) + "], \"low\": [" + low +
         "], \"high\": [" + high + "]}";
}

bool is_scratch(const std::string& name) {
  return !name.empty() && name[0] == '.' && (name.find(".tmp-") != std::string::npos || name.find(".old-") != std::string::npos);
}

// Our own Minari export: only data/ with metadata.json (carrying our marker) and main_data.hdf5.
bool is_own_minari_folder(const fs::path& dir, std::string& why) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name != "data" && !is_scratch(name)) {
      why = "it holds " + name;
      return false;
    }
  }
  for (fs::directory_iterator it(dir / "data", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name != kMetadataFile && name != kMainFile && !is_scratch(name)) {
      why = "it holds data/" + name;
      return false;
    }
  }
  try {
    const json meta = parse_json_text(read_file(dir / "data" / kMetadataFile), "metadata.json");
    if (meta.is_object() && meta.contains("dicestack") && meta["dicestack"].is_object() &&
        meta["dicestack"].value("format", "") == kMinariFormat)
      return true;
  } catch (const std::exception&) {
  }
  why = "its data/metadata.json is not a dicestack export's";
  return false;
}

void check_minari_replaceable(const fs::path& dir) {
  std::error_code ec;
  const auto st = fs::symlink_status(dir, ec);
  if (ec || st.type() == fs::file_type::not_found) return;
  if (st.type() != fs::file_type::directory)
    throw InputError(dir.string() + ": exists and is not a folder; refusing to replace it: choose another --out or remove it yourself");
  if (fs::is_empty(dir, ec)) return;
  std::string why;
  if (!is_own_minari_folder(dir, why))
    throw InputError(dir.string() + ": exists and is not a dicestack Minari export (" + why +
                     "); refusing to replace it: choose another --out or remove it yourself");
}

long episode_number(const std::string& name) {
  if (name.rfind("episode_", 0) != 0 || name.size() == 8 || name.size() > 18) return -1;
  long n = 0;
  const auto r = std::from_chars(name.data() + 8, name.data() + name.size(), n);
  if (r.ec != std::errc() || r.ptr != name.data() + name.size() || n < 0) return -1;
  return n;
}

std::int64_t meta_integer(const json& meta, const char* key, const std::string& where) {
  if (!meta.contains(key) || !meta[key].is_number_integer() || meta[key].get<std::int64_t>() < 0)
    throw InputError(where + ": \"" + key + "\" must be a non-negative integer");
  return meta[key].get<std::int64_t>();
}

// The flags of one episode: 0/1, and only the last step may be 1.
std::vector<double> end_flags(hid_t group, const char* name, const std::string& where, std::size_t steps) {
  const h5::Array a = read_shaped(group, name, where, steps, 0, true);
  for (std::size_t t = 0; t < steps; ++t) {
    if (a.values[t] != 0.0 && a.values[t] != 1.0) throw InputError(where + ": item " + std::to_string(t) + " is neither 0 nor 1");
    if (a.values[t] != 0.0 && t + 1 < steps)
      throw InputError(where + ": item " + std::to_string(t) + " is set before the episode's last step");
  }
  return a.values;
}

// Gymnasium's EnvSpec.to_json of the environment `import dicestack` registers, with this world:
// minari's recover_environment() makes it with gymnasium.make. Fields that differ between
// Gymnasium versions (order_enforce, autoreset, apply_api_compatibility) are left to defaults.
json env_spec(const WorldConfig& world) {
  return {{"id", kGymEnvId},
          {"entry_point", "dicestack.env:DiceStackEnv"},
          {"reward_threshold", nullptr},
          {"nondeterministic", false},
          {"max_episode_steps", nullptr},  // the environment truncates at the world's episode.max_steps itself
          {"disable_env_checker", false},
          {"kwargs", {{"world", json::parse(to_json(world))}}},
          {"additional_wrappers", json::array()},
          {"vector_entry_point", "dicestack.vector_env:DiceStackVectorEnv"}};
}

// Reads data/metadata.json: it must exist, be a JSON object, and name HDF5 storage.
json read_minari_metadata(const fs::path& meta_path) {
  const std::string M = meta_path.string();
  std::error_code ec;
  if (fs::status(meta_path, ec).type() == fs::file_type::not_found) throw InputError(M + ": missing; not a Minari dataset");
  json meta = parse_json_text(read_file(meta_path), M);
  if (!meta.is_object()) throw InputError(M + ": must be a JSON object");
  if (!meta.contains("data_format") || meta["data_format"] != "hdf5")
    throw InputError(M + ": \"data_format\" must be \"hdf5\" (the only storage dicestack reads)");
  return meta;
}

// The world, description and provenance from metadata.json's "dicestack" object (our marker), if it has one.
void read_minari_set_record(const json& meta, const std::string& M, DemoSet& set) {
  if (!meta.contains("dicestack")) return;
  const json& r = meta["dicestack"];
  if (!r.is_object() || r.value("format", "") != kMinariFormat)
    throw InputError(M + ": \"dicestack\" must be an object with \"format\": \"" + kMinariFormat + "\"");
  if (!r.contains("version") || !r["version"].is_number_integer())
    throw InputError(M + ": \"dicestack\".\"version\" must be an integer");
  if (r["version"].get<std::int64_t>() > kInteropFormatVersion)
    throw InputError(M + ": format version " + std::to_string(r["version"].get<std::int64_t>()) +
                     " is newer than this dicestack reads (" + std::to_string(kInteropFormatVersion) + "); upgrade dicestack");
  if (!r.contains("world")) throw InputError(M + ": \"dicestack\" has no \"world\"");
  set.world = world_config_from_json(r["world"].dump(), M + " \"dicestack\".\"world\"");
  set.description = r.value("description", set.description);
  set.provenance = r.value("provenance", "");
}

// The episode_<n> groups of the main file, sorted; exactly metadata.json's total_episodes of
// them, numbered from 0 without gaps.
std::vector<std::string> list_minari_episodes(const h5::ReadFile& f, const std::string& M, std::int64_t total_episodes) {
  const std::string& F = f.name();
  std::vector<std::pair<long, std::string>> episodes;
  for (const auto& name : h5::members(f.root(), F)) {
    const long n = episode_number(name);
    if (n < 0) throw InputError(F + ": " + name.substr(0, 60) + ": not an episode_<n> group");
    episodes.emplace_back(n, name);
  }
  std::sort(episodes.begin(), episodes.end());
  if (static_cast<std::int64_t>(episodes.size()) != total_episodes)
    throw InputError(M + ": \"total_episodes\" is " + std::to_string(total_episodes) + ", but " + F + " holds " +
                     std::to_string(episodes.size()) + " episodes");
  if (episodes.empty()) throw InputError(F + ": holds no episode");
  std::vector<std::string> names;
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    if (episodes[i].first != static_cast<long>(i))
      throw InputError(F + ": episode_" + std::to_string(i) + ": missing (episodes are numbered from 0 without gaps)");
    names.push_back(episodes[i].second);
  }
  return names;
}

// An arm's readings as the environment's infos give them at reset and after each step: the links,
// and the torques the joints held over the step (none before the first).
void write_minari_arm(hid_t episode, const Episode& e) {
  const hsize_t rows = e.size() + 1;
  const h5::Id infos = h5::create_group(episode, "infos");
  h5::write_f64(infos.get(), "link_angles", {rows, 3}, link_rows(e, false).data());
  h5::write_f64(infos.get(), "link_rates", {rows, 3}, link_rows(e, true).data());
  if (e.joint_torques.empty()) return;
  std::vector<double> torques(4, 0.0);
  for (const auto& tau : e.joint_torques) torques.insert(torques.end(), tau.begin(), tau.end());
  h5::write_f64(infos.get(), "joint_torques", {rows, 4}, torques.data());
}

// write_minari_arm's infos back, where the episode has them.
void read_minari_arm(hid_t episode, const std::string& where, std::size_t steps, Episode& e) {
  if (!h5::exists(episode, "infos/link_angles")) {
    if (h5::exists(episode, "infos/joint_torques"))
      throw InputError(where + "/infos/joint_torques: an arm's joint torques need its links (infos/link_angles, infos/link_rates)");
    return;
  }
  const h5::Array angles = read_shaped(episode, "infos/link_angles", where + "/infos/link_angles", steps + 1, 3);
  const h5::Array rates = read_shaped(episode, "infos/link_rates", where + "/infos/link_rates", steps + 1, 3);
  links_from_rows(angles, rates, e);
  if (!h5::exists(episode, "infos/joint_torques")) return;
  const h5::Array torques = read_shaped(episode, "infos/joint_torques", where + "/infos/joint_torques", steps + 1, 4);
  e.joint_torques.assign(steps, {});
  for (std::size_t t = 0; t < steps; ++t)
    std::copy_n(torques.values.begin() + static_cast<std::ptrdiff_t>(4 * (t + 1)), 4, e.joint_torques[t].begin());
}

// Reads and checks the main file's group `name`, the episode at `index` of the dataset in `dir`.
Episode read_minari_episode(const h5::ReadFile& f, const std::string& name, std::size_t index, const fs::path& dir,
                            const WorldConfig& world) {
  const auto& limit = world.action.limit;
  const std::string where = f.name() + ": " + name;
  const h5::Id g = h5::open_group(f.root(), name, where);
  const h5::Array actions = read_rows(g.get(), "actions", where + "/actions", kActionDim);
  const std::size_t steps = actions.dims[0];
  const h5::Array obs = read_shaped(g.get(), "observations", where + "/observations", steps + 1, kStateDim);
  const h5::Array rewards = read_shaped(g.get(), "rewards", where + "/rewards", steps, 0);
  const auto terminations = end_flags(g.get(), "terminations", where + "/terminations", steps);
  const auto truncations = end_flags(g.get(), "truncations", where + "/truncations", steps);
  if (const auto n = h5::read_attr_int(g.get(), "total_steps", where); n && *n != static_cast<std::int64_t>(steps))
    throw InputError(where + ": attribute total_steps is " + std::to_string(*n) + ", but actions has " +
                     std::to_string(steps) + " rows");

  Episode e;
  e.states.resize(steps);
  State final_state{};
  for (std::size_t t = 0; t <= steps; ++t) {
    State& s = t < steps ? e.states[t] : final_state;
    std::copy_n(obs.values.begin() + static_cast<std::ptrdiff_t>(t * kStateDim), kStateDim, s.begin());
  }
  e.final_state = final_state;
  e.actions.resize(steps);
  for (std::size_t t = 0; t < steps; ++t)
    for (std::size_t k = 0; k < kActionDim; ++k) {
      const double a = actions.values[t * kActionDim + k];
      if (std::abs(a) > limit[k])
        throw InputError(where + "/actions: row " + std::to_string(t) + " column " + std::to_string(k) +
                         " is outside the world's action.limit (" + py_number(limit[k]) + ")");
      e.actions[t][k] = a;
    }
  e.rewards = rewards.values;
  e.terminated = terminations.back() != 0.0;
  e.truncated = truncations.back() != 0.0;
  read_minari_arm(g.get(), where, steps, e);
  read_episode_record(g.get(), where, index, "seed", "minari " + dir.string() + " " + name, world, e);
  check_read_episode(e, where);
  return e;
}

}  // namespace

std::string default_minari_dataset_id(const fs::path& set_dir) {
  std::string name = set_dir.filename().string();
  if (name.empty()) name = set_dir.parent_path().filename().string();
  std::string clean;
  for (char c : name) clean += std::isalnum(static_cast<unsigned char>(c)) || c == '_' ? c : '-';
  while (!clean.empty() && clean.front() == '-') clean.erase(clean.begin());
  while (!clean.empty() && clean.back() == '-') clean.pop_back();
  if (clean.empty()) clean = "demos";
  return "dicestack/" + clean + "-v0";
}

void export_minari(const DemoSet& set, const fs::path& dir, const std::string& dataset_id) {
  validate(set.world);
  require_transitions(set.episodes, dir.string());
  require_cup_actions(set.episodes, dir.string());
  for (const auto& e : set.episodes) check_episode(e);
  const bool arm = arm_episodes(set.episodes, dir.string());
  check_minari_replaceable(dir);

  h5::MemoryFile f;
  std::int64_t total_steps = 0;
  for (std::size_t i = 0; i < set.episodes.size(); ++i) {
    const Episode& e = set.episodes[i];
    const h5::Id g = h5::create_group(f.root(), "episode_" + std::to_string(i));
    const hsize_t steps = e.size();
    total_steps += static_cast<std::int64_t>(steps);
    std::vector<double> observations, actions;
    for (const auto& s : e.states) observations.insert(observations.end(), s.begin(), s.end());
    observations.insert(observations.end(), e.final_state->begin(), e.final_state->end());
    for (const auto& a : e.actions) actions.insert(actions.end(), a.begin(), a.end());
    std::vector<std::uint8_t> terminations(steps, 0), truncations(steps, 0);
    terminations.back() = e.terminated;
    truncations.back() = e.truncated;
    h5::attr_i64(g.get(), "id", static_cast<std::int64_t>(i));
    h5::attr_u64(g.get(), "seed", e.seed);
    h5::attr_i64(g.get(), "total_steps", static_cast<std::int64_t>(steps));
    h5::write_f64(g.get(), "observations", {steps + 1, kStateDim}, observations.data());
    h5::write_f64(g.get(), "actions", {steps, kActionDim}, actions.data());
    h5::write_f64(g.get(), "rewards", {steps}, e.rewards.data());
    h5::write_bool(g.get(), "terminations", terminations);
    h5::write_bool(g.get(), "truncations", truncations);
    if (arm) write_minari_arm(g.get(), e);
    h5::attr_string(g.get(), "dicestack_name", e.name);
    h5::attr_string(g.get(), "dicestack_origin", e.origin);
    h5::attr_string(g.get(), "dicestack_sources", sources_text(e.sources));
    h5::attr_string(g.get(), "dicestack_outcome", outcome_json(e.outcome).dump());
  }
  const std::string bytes = f.image();

  const DiceEnv env(set.world);
  json record = set_record(set, kMinariFormat);
  record["world"] = json::parse(to_json(set.world));
  json meta = {{"total_episodes", set.episodes.size()},
               {"total_steps", total_steps},
               {"data_format", "hdf5"},
               {"observation_space", box_text(env.observation_space())},
               {"action_space", box_text(env.action_space())},
               {"dataset_id", dataset_id},
               {"description", set.description},
               {"minari_version", kMinariVersion},
               {"dataset_size", std::round(static_cast<double>(bytes.size()) / 1e5) / 10.0},  // MB, one decimal
               {"env_spec", env_spec(set.world).dump()},
               {"dicestack", record}};
  const auto ours = [](const fs::path& p) {
    std::string why;
    return is_own_minari_folder(p, why);
  };
  replace_folder(dir, ours, check_minari_replaceable, [&](const fs::path& tmp) {
    fs::create_directory(tmp / "data");
    const Ownership fresh = Ownership::unchecked("file of a fresh folder");
    AtomicFile main(tmp / "data" / kMainFile, fresh, AtomicFile::Leftovers::skip);
    main.stream().write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    main.commit();
    AtomicFile m(tmp / "data" / kMetadataFile, fresh, AtomicFile::Leftovers::skip);
    m.stream() << meta.dump() << '\n';
    m.commit();
  });
}

DemoSet import_minari(const fs::path& dir, const WorldConfig& fallback_world) {
  if (!fs::is_directory(dir)) throw InputError(dir.string() + ": not a folder (a Minari dataset is a folder holding data/)");
  const fs::path meta_path = dir / "data" / kMetadataFile;
  const std::string M = meta_path.string();
  const json meta = read_minari_metadata(meta_path);
  const auto total_episodes = meta_integer(meta, "total_episodes", M);
  const auto total_steps = meta_integer(meta, "total_steps", M);
  DemoSet set;
  set.world = fallback_world;
  set.description = meta.contains("description") && meta["description"].is_string() ? meta["description"].get<std::string>()
                                                                                     : "imported from Minari dataset " + dir.string();
  read_minari_set_record(meta, M, set);

  const fs::path main_path = dir / "data" / kMainFile;
  h5::ReadFile f(main_path);
  const std::vector<std::string> episodes = list_minari_episodes(f, M, total_episodes);
  std::int64_t steps_seen = 0;
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    Episode e = read_minari_episode(f, episodes[i], i, dir, set.world);
    steps_seen += static_cast<std::int64_t>(e.actions.size());
    set.episodes.push_back(std::move(e));
  }
  if (steps_seen != total_steps)
    throw InputError(M + ": \"total_steps\" is " + std::to_string(total_steps) + ", but the episodes hold " +
                     std::to_string(steps_seen) + " steps");
  return set;
}

}  // namespace dicestack
