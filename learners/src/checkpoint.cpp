#include "checkpoint.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>
#include <map>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/core/read_file.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>

namespace dicestack {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kFormat = "dicestack-checkpoint";
// 1: the same fields without "version" (and, before the marker, without "format"); 2: adds
// "version"; 3: "run"'s learner options as an object of key -> value, not one "k=v, k=v" text;
// 4: "run"'s regressor settings as "regressor_params", an object of every schema parameter ->
// its parsed value (JSON number, boolean or string), not the --set text "regressor_sets";
// 5: "run"'s learner options as the run used them (resolved_option: tracker_paths -1 and retry
// auto as the feature map resolved them).
constexpr int kVersion = 5;

// "data-<digits>" or "best-<digits>.model" (suffix empty or ".model").
bool numbered(const std::string& name, const std::string& prefix, const std::string& suffix) {
  if (name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0) return false;
  if (name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) return false;
  for (std::size_t i = prefix.size(); i < name.size() - suffix.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) return false;
  return true;
}

// A checkpoint's learner options as key -> value: an object (version 3) or, before, the text
// "k=v, k=v" (values never hold ", ": they are numbers, booleans and choice names).
std::map<std::string, std::string> saved_options(const json& saved) {
  std::map<std::string, std::string> out;
  if (saved.is_object()) {
    for (const auto& [k, v] : saved.items()) out[k] = v.is_string() ? v.get<std::string>() : v.dump();
  } else if (saved.is_string()) {
    const std::string text = saved.get<std::string>();
    for (std::size_t at = 0; at < text.size();) {
      std::size_t end = text.find(", ", at);
      if (end == std::string::npos) end = text.size();
      const std::string kv = text.substr(at, end - at);
      const std::size_t eq = kv.find('=');
      if (eq != std::string::npos) out[kv.substr(0, eq)] = kv.substr(eq + 1);
      at = end + 2;
    }
  }
  return out;
}

// What a learner's option meant in checkpoints written before the option existed: the behaviour
// then, which is its default unless listed here (DaD corrected towards whole states before it
// had "target"; the tracker did not narrow a path before it had "tracker_shrink", nor refine one
// before "tracker_refine", and refined one path once before "tracker_refine_restarts").
std::string value_before(const std::string& learner, const std::string& key) {
  if (learner == "dad" && key == "target") return "state";
  if (key == "tracker_shrink" || key == "tracker_refine") return "0";
  if (key == "tracker_refine_restarts") return "1";
  for (const auto& p : LearnerRegistry::global().info(learner).params)
    if (p.name == key) return p.default_value;
  return "";
}

// An option's value as a run uses it: the defaults that depend on the run's feature map
// (tracker_paths -1; retry auto) resolved with it, the rest as given. Version 5 writes options
// so; older checkpoints saved them as given, and are resolved with their own map when read.
std::string resolved_option(const std::string& key, const std::string& text, const std::string& features) {
  const bool by_map = (key == "tracker_paths" && text == "-1") || (key == "retry" && text == "auto");
  if (!by_map || features.empty()) return text;
  try {
    if (key == "retry") return expert_retries(text, features) ? "true" : "false";
    return std::to_string(tracker_paths_for(-1, features));
  } catch (const ConfigError&) {  // a map this version does not know: compared as written
    return text;
  }
}

// The feature map a run recorded ("" when none).
std::string run_features(const json& run) {
  return run.contains("features") && run["features"].is_string() ? run["features"].get<std::string>() : "";
}

// Every parameter of `schema` -> its value in `params`, typed: what a run's regressor settings mean.
json typed_params(const std::vector<ParamSpec>& schema, const Params& params) {
  json out = json::object();
  for (const auto& spec : schema) {
    switch (spec.type) {
      case ParamType::integer: out[spec.name] = params.integer(spec.name); break;
      case ParamType::real: out[spec.name] = params.real(spec.name); break;
      case ParamType::boolean: out[spec.name] = params.boolean(spec.name); break;
      case ParamType::choice:
      case ParamType::text: out[spec.name] = params.choice(spec.name); break;
    }
  }
  return out;
}

// Versions 1-3 saved the --set assignments joined by spaces: "k=3 metric=l2". A piece without
// "=" continues the previous value (a text value holding a space).
std::vector<std::string> split_sets(const std::string& text) {
  std::vector<std::string> out;
  for (std::size_t at = 0; at <= text.size();) {
    std::size_t end = text.find(' ', at);
    if (end == std::string::npos) end = text.size();
    const std::string piece = text.substr(at, end - at);
    if (!piece.empty() && (piece.find('=') != std::string::npos || out.empty())) out.push_back(piece);
    else if (!out.empty()) out.back() += " " + piece;
    at = end + 1;
  }
  return out;
}

std::string excerpt(const json& j) {
  const std::string text = j.dump();
  return text.size() <= 60 ? text : text.substr(0, 57) + "...";
}

std::string difference(const std::string& what, const json& saved, const json& now) {
  return what + " " + excerpt(saved) + " in the checkpoint, " + now.dump() + " in this run";
}

// A checkpoint's regressor settings against this run's (`now`, from run_settings), value by
// parsed value: version 4's "regressor_params", or the "regressor_sets" text of versions 1-3
// parsed through this run's schema. A parameter the checkpoint does not name (added to the
// regressor since) had its default. Each difference is passed to `note`.
void compare_regressor_params(const json& saved_run, const json& now, const LearnContext& c,
                              const std::function<void(std::string)>& note) {
  const auto& schema = c.registry->info(c.regressor).params;
  json saved;
  if (saved_run.contains("regressor_params")) {
    saved = saved_run["regressor_params"];
    if (!saved.is_object()) return note(difference("regressor_params", saved, now));
    const json defaults = typed_params(schema, Params(schema, {}, c.regressor));
    for (const auto& [k, v] : defaults.items())
      if (!saved.contains(k)) saved[k] = v;
  } else {
    const json text = saved_run.value("regressor_sets", json());
    if (!text.is_string()) return note(difference("regressor_sets", text, now));
    try {
      saved = typed_params(schema, Params(schema, split_sets(text.get<std::string>()), c.regressor));
    } catch (const ConfigError& e) {
      return note("regressor settings " + excerpt(text) + " in the checkpoint, which this dicestack refuses (" +
                  e.what() + ")");
    }
  }
  for (const auto& [k, v] : saved.items())
    if (!now.contains(k)) note(difference("regressor parameter " + k, v, json("(not a parameter now)")));
  for (const auto& [k, v] : now.items())
    if (saved.value(k, json()) != v) note(difference("regressor parameter " + k, saved.value(k, json()), v));
}

}  // namespace

json curve_to_json(const std::vector<CurvePoint>& curve) {
  json out = json::array();
  for (const auto& p : curve)
    out.push_back({{"iteration", p.iteration}, {"window", p.window}, {"dataset_rows", p.dataset_rows},
                   {"deviation", p.deviation}, {"stacked_rate", p.stacked_rate},
                   {"realistic_success_rate", p.realistic_success_rate}, {"dice_in_cup_mean", p.dice_in_cup_mean}});
  return out;
}

void save_checkpoint(const fs::path& dir, int iteration, json state, const std::string& state_file,
                     const LearnContext& c, const std::vector<Episode>& data, const std::string& description) {
  fs::create_directories(dir);
  DemoSet set;
  set.world = c.world;
  set.description = description;
  set.provenance = "dicestack " + description + ", seed " + std::to_string(c.seed) + ", regressor " + c.regressor;
  set.episodes = data;
  const std::string folder = "data-" + std::to_string(iteration);
  write_demo_set(set, dir / folder);
  state["format"] = kFormat;
  state["version"] = kVersion;
  state["iteration"] = iteration;
  state["data"] = folder;
  AtomicFile f(dir / state_file, Ownership::json_object("dicestack checkpoint state", kFormat, {"iteration", "data"}));
  f.stream() << state.dump();
  f.commit();
  for (const auto& entry : fs::directory_iterator(dir)) {  // older iterations' data, now unreferenced
    const std::string name = entry.path().filename().string();
    if (name != folder && numbered(name, "data-", "") && is_own_demo_set(entry.path())) fs::remove_all(entry.path());
  }
}

void remove_old_best_models(const fs::path& dir, const std::string& keep) {
  const Ownership model = model_ownership();
  for (const auto& entry : fs::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name != keep && numbered(name, "best-", ".model") && entry.is_regular_file() && model.recognises(entry.path()))
      fs::remove(entry.path());
  }
}

json run_settings(const LearnContext& c, const std::vector<std::pair<std::string, std::string>>& learner_options,
                  const std::vector<std::string>& extendable) {
  json options = json::object();
  for (const auto& [key, value] : learner_options)
    if (std::find(extendable.begin(), extendable.end(), key) == extendable.end())
      options[key] = resolved_option(key, value, c.features);
  const auto& schema = c.registry->info(c.regressor).params;
  return {{"regressor", c.regressor},
          {"regressor_params", typed_params(schema, Params(schema, c.regressor_sets, c.regressor))},
          {"features", c.features},
          {"seed", std::to_string(c.seed)},
          {"learner_options", options},
          {"demonstrations", std::to_string(c.demos.size())},
          {"held_out", std::to_string(c.held_out.size())},
          {"world", std::to_string(world_hash(c.world))}};
}

CheckpointState::CheckpointState(fs::path path, json state) : path_(std::move(path)), json_(std::move(state)) {
  // States written before the marker (dicestack 0.3) hold "iteration" and "data" without it.
  const bool marked = json_.is_object() && json_.value("format", json()) == kFormat;
  if (!marked && !(json_.is_object() && !json_.contains("format") && json_.contains("iteration") && json_.contains("data")))
    throw InputError(path_.string() + ": not a checkpoint state (no \"format\": \"" + kFormat + "\")");
  const std::int64_t version = json_.contains("version") ? integer("version", 1, INT64_MAX) : 1;
  if (version > kVersion)
    throw InputError(path_.string() + ": format version " + std::to_string(version) + " is newer than this dicestack reads (" +
                     std::to_string(kVersion) + "); upgrade dicestack");
  iteration_ = static_cast<int>(integer("iteration", 0, 1'000'000));
  if (file("data").string() != "data-" + std::to_string(iteration_))
    fail("data", "must name this iteration's folder \"data-" + std::to_string(iteration_) + "\"");
  if (!json_.contains("curve") || !json_["curve"].is_array()) fail("curve", "must be an array");
  for (std::size_t i = 0; i < json_["curve"].size(); ++i) {
    const json& p = json_["curve"][i];
    const std::string at = "curve[" + std::to_string(i) + "]";
    auto get = [&](const char* key, bool whole) {
      const json v = p.is_object() ? p.value(key, json()) : json();
      if (!v.is_number() || !std::isfinite(v.get<double>()) || (whole && (!v.is_number_integer() || v.get<std::int64_t>() < 0)))
        fail(at + "." + key, std::string("must be a ") + (whole ? "non-negative integer" : "finite number") + ", got " + excerpt(v));
      return v;
    };
    curve_.push_back({get("iteration", true).get<int>(), get("window", true).get<int>(),
                      get("dataset_rows", true).get<std::size_t>(), get("deviation", false).get<double>(),
                      get("stacked_rate", false).get<double>(), get("realistic_success_rate", false).get<double>(),
                      get("dice_in_cup_mean", false).get<double>()});
  }
}

void CheckpointState::fail(const std::string& key, const std::string& what) const {
  throw InputError(path_.string() + ": field \"" + key + "\" " + what);
}

std::int64_t CheckpointState::integer(const std::string& key, std::int64_t lo, std::int64_t hi) const {
  const json v = json_.value(key, json());
  if (!v.is_number_integer() || (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX)) ||
      v.get<std::int64_t>() < lo || v.get<std::int64_t>() > hi)
    fail(key, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + excerpt(v));
  return v.get<std::int64_t>();
}

double CheckpointState::number(const std::string& key) const {
  const json v = json_.value(key, json());
  if (!v.is_number() || !std::isfinite(v.get<double>())) fail(key, "must be a finite number, got " + excerpt(v));
  return v.get<double>();
}

fs::path CheckpointState::file(const std::string& key) const {
  const json v = json_.value(key, json());
  if (!v.is_string()) fail(key, "must be a file name, got " + excerpt(v));
  const std::string name = v.get<std::string>();
  if (name.empty() || name == "." || name == ".." || name.find('/') != std::string::npos || name.find('\0') != std::string::npos)
    fail(key, "must be a file name inside the checkpoint folder, got " + excerpt(v));
  return name;
}

std::vector<Episode> CheckpointState::data() const { return read_demo_set(path_.parent_path() / file("data")).episodes; }

std::optional<CheckpointState> load_checkpoint_state(const LearnContext& c, const std::string& state_file, const json& run) {
  if (!c.resume || c.checkpoint_dir.empty() || !fs::exists(c.checkpoint_dir / state_file)) return std::nullopt;
  const fs::path path = c.checkpoint_dir / state_file;
  json state;
  try {
    state = parse_json_limited<json>(read_file(path), path.string());
  } catch (const json::exception& e) {
    throw InputError(path.string() + ": not a checkpoint state (" + e.what() + ")");
  }
  CheckpointState checked(path, state);
  if (state.contains("run") && !state["run"].is_object())
    throw InputError(path.string() + ": field \"run\" must be an object");
  if (state.contains("run")) {  // states written before runs were recorded have none to compare
    std::string differences;
    auto note = [&](std::string text) { differences += (differences.empty() ? "" : "; ") + std::move(text); };
    auto differ = [&](const std::string& what, const json& saved, const json& now) { note(difference(what, saved, now)); };
    const json& saved_run = state["run"];
    const bool same_regressor = saved_run.value("regressor", json()) == run.value("regressor", json());
    for (const auto& [key, value] : run.items()) {
      const json saved = saved_run.value(key, json());
      if (key == "regressor_params") {
        // Parsed values, parameter by parameter (so "08" and "8" agree); only for the same regressor.
        if (same_regressor) compare_regressor_params(saved_run, value, c, note);
        continue;
      }
      if (key != "learner_options") {
        if (saved != value) differ(key, saved, value);
        continue;
      }
      // Option by option, parsed: an option added since the checkpoint was written matches when
      // this run gives it the value its absence meant.
      const auto before = saved_options(saved);
      const std::string learner = fs::path(state_file).stem().string();
      const auto option_then = [&](const std::string& k) {
        const auto it = before.find(k);
        return it != before.end() ? it->second : value_before(learner, k);
      };
      const json expert_now = value.value("expert", json());
      const bool tracker_run = option_then("expert") == "tracker" || expert_now == "tracker";
      const bool refined = option_then("tracker_refine") != "0" || value.value("tracker_refine", json("0")) != "0";
      for (const auto& [k, v] : value.items()) {
        if (!tracker_run && k.starts_with("tracker_")) continue;  // nothing to a run of another expert
        if (!refined && k.starts_with("tracker_refine_")) continue;  // nothing when neither run refines
        const std::string now = v.get<std::string>();
        const auto it = before.find(k);
        const std::string then = option_then(k);
        if (resolved_option(k, then, run_features(saved_run)) != resolved_option(k, now, run_features(run)))
          differ("option " + k, it != before.end() ? json(then) : json("(absent)"), json(now));
      }
    }
    if (!differences.empty())
      throw InputError(path.string() + ": cannot resume a run made with other settings: " + differences +
                       " (use the same settings, or another --checkpoint)");
  }
  return checked;
}

CurvePoint measure_policy(const std::shared_ptr<const Model>& model, const LearnContext& c,
                          const std::vector<Episode>& fallback, int iteration, std::size_t rows) {
  const auto& demos = c.held_out.empty() ? fallback : c.held_out;
  const Tracking t = track_demos([&] { return std::make_unique<ModelPolicy>(model); }, demos, c.world, c.threads, *c.cluster);
  return {iteration, 0, rows, t.deviation, t.stats.stacked.value, t.stats.realistic_success.value, t.stats.dice_in_cup_mean};
}

}  // namespace dicestack
