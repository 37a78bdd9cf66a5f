#include <dicestack/learners/learner.hpp>

#include <cctype>
#include <algorithm>
#include <fstream>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>

#include "checkpoint.hpp"

namespace dicestack {

void register_bc(LearnerRegistry&);
void register_dagger(LearnerRegistry&);
void register_dad(LearnerRegistry&);
void register_dart(LearnerRegistry&);

LearnerRegistry& LearnerRegistry::global() {
  static LearnerRegistry* registry = [] {
    auto* r = new LearnerRegistry;
    register_bc(*r);
    register_dagger(*r);
    register_dad(*r);
    register_dart(*r);
    return r;
  }();
  return *registry;
}

void LearnerRegistry::add(LearnerInfo info) {
  if (entries_.contains(info.name)) throw ConfigError("learner \"" + info.name + "\" registered twice");
  std::string name = info.name;
  entries_.emplace(std::move(name), std::move(info));
}

const LearnerInfo& LearnerRegistry::info(std::string_view name) const { return registered_entry(entries_, name, "learner"); }

std::unique_ptr<Learner> LearnerRegistry::create(std::string_view name, const std::vector<std::string>& assignments) const {
  const LearnerInfo& i = info(name);
  return i.factory(i.name, Params(i.params, assignments, i.name));
}

std::vector<std::string> LearnerRegistry::names() const { return registered_names(entries_); }

std::shared_ptr<Model> fit_model(const LearnContext& c, const std::vector<Episode>& data, std::uint64_t seed) {
  if (data.empty()) throw InputError("no demonstrations to learn from");
  const FeatureMap& features = feature_map(c.features);
  const Dataset d = make_dataset(data, features);
  auto model = std::make_shared<Model>(
      Model::train(c.registry->create(c.regressor, c.regressor_sets), d.x, d.y, seed, nullptr, features));
  model->record["regressor_params"] = model->regressor().params().summary();
  model->record["rows"] = std::to_string(d.rows());
  model->record["episodes"] = std::to_string(d.episodes());
  model->record["seed"] = std::to_string(seed);
  return model;
}

namespace fs = std::filesystem;

namespace {

constexpr const char* kCurveHeader = "iteration,window,dataset_rows,deviation,stacked_rate,realistic_success_rate,dice_in_cup_mean";
constexpr const char* kCheckpointFormat = "dicestack-checkpoint";

// "data-<digits>" or "best-<digits>.model" (suffix empty or ".model").
bool numbered(const std::string& name, const std::string& prefix, const std::string& suffix) {
  if (name.size() <= prefix.size() + suffix.size() || name.rfind(prefix, 0) != 0) return false;
  if (name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) return false;
  for (std::size_t i = prefix.size(); i < name.size() - suffix.size(); ++i)
    if (!std::isdigit(static_cast<unsigned char>(name[i]))) return false;
  return true;
}

}  // namespace

void write_curve_csv(const std::vector<CurvePoint>& curve, const fs::path& path) {
  AtomicFile f(path, Ownership::first_line("dicestack learning curve CSV", {kCurveHeader}));
  auto& os = f.stream();
  os.precision(17);
  os << kCurveHeader << '\n';
  for (const auto& p : curve)
    os << p.iteration << ',' << p.window << ',' << p.dataset_rows << ',' << p.deviation << ',' << p.stacked_rate << ','
       << p.realistic_success_rate << ',' << p.dice_in_cup_mean << '\n';
  f.commit();
}

nlohmann::json curve_to_json(const std::vector<CurvePoint>& curve) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& p : curve)
    out.push_back({{"iteration", p.iteration}, {"window", p.window}, {"dataset_rows", p.dataset_rows},
                   {"deviation", p.deviation}, {"stacked_rate", p.stacked_rate},
                   {"realistic_success_rate", p.realistic_success_rate}, {"dice_in_cup_mean", p.dice_in_cup_mean}});
  return out;
}

std::vector<CurvePoint> curve_from_json(const nlohmann::json& json) {
  std::vector<CurvePoint> out;
  for (const auto& p : json)
    out.push_back({p.at("iteration"), p.at("window"), p.at("dataset_rows"), p.at("deviation"), p.at("stacked_rate"),
                   p.at("realistic_success_rate"), p.at("dice_in_cup_mean")});
  return out;
}

void save_checkpoint(const fs::path& dir, int iteration, nlohmann::json state, const std::string& state_file,
                     const LearnContext& c, const std::vector<Episode>& data, const std::string& description) {
  fs::create_directories(dir);
  DemoSet set;
  set.world = c.world;
  set.description = description;
  set.provenance = "dicestack " + description + ", seed " + std::to_string(c.seed) + ", regressor " + c.regressor;
  set.episodes = data;
  const std::string folder = "data-" + std::to_string(iteration);
  write_demo_set(set, dir / folder);
  state["format"] = kCheckpointFormat;
  state["iteration"] = iteration;
  state["data"] = folder;
  AtomicFile f(dir / state_file, Ownership::json_object("dicestack checkpoint state", kCheckpointFormat, {"iteration", "data"}));
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

std::vector<Episode> load_checkpoint_data(const LearnContext& c, const nlohmann::json& state) {
  return read_demo_set(c.checkpoint_dir / state.at("data").get<std::string>()).episodes;
}

nlohmann::json run_settings(const LearnContext& c, const Params& learner_params,
                            const std::vector<std::string>& extendable) {
  std::string sets, options;
  for (const auto& s : c.regressor_sets) sets += (sets.empty() ? "" : " ") + s;
  for (const auto& [key, value] : learner_params.as_text())
    if (std::find(extendable.begin(), extendable.end(), key) == extendable.end())
      options += (options.empty() ? "" : ", ") + key + "=" + value;
  return {{"regressor", c.regressor},
          {"regressor_sets", sets},
          {"features", c.features},
          {"seed", std::to_string(c.seed)},
          {"learner_options", options},
          {"demonstrations", std::to_string(c.demos.size())},
          {"held_out", std::to_string(c.held_out.size())},
          {"world", std::to_string(world_hash(c.world))}};
}

nlohmann::json load_checkpoint_state(const LearnContext& c, const std::string& state_file, const nlohmann::json& run) {
  if (!c.resume || c.checkpoint_dir.empty() || !fs::exists(c.checkpoint_dir / state_file)) return nullptr;
  const fs::path path = c.checkpoint_dir / state_file;
  nlohmann::json state;
  try {
    state = parse_json_limited<nlohmann::json>(std::ifstream(path), path.string());
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path.string() + ": not a checkpoint state (" + e.what() + ")");
  }
  if (!state.is_object()) throw InputError(path.string() + ": not a checkpoint state (not a JSON object)");
  if (state.contains("run") && !state["run"].is_object())
    throw InputError(path.string() + ": not a checkpoint state (\"run\" is not an object)");
  if (state.contains("run")) {  // states written before runs were recorded have none to compare
    std::string differences;
    for (const auto& [key, value] : run.items()) {
      const nlohmann::json saved = state["run"].value(key, nlohmann::json());
      if (saved != value)
        differences += (differences.empty() ? "" : "; ") + key + " " + saved.dump() + " in the checkpoint, " +
                       value.dump() + " in this run";
    }
    if (!differences.empty())
      throw InputError(path.string() + ": cannot resume a run made with other settings: " + differences +
                       " (use the same settings, or another --checkpoint)");
  }
  return state;
}

CurvePoint measure_policy(const std::shared_ptr<const Model>& model, const LearnContext& c,
                          const std::vector<Episode>& fallback, int iteration, std::size_t rows) {
  const auto& demos = c.held_out.empty() ? fallback : c.held_out;
  const Tracking t = track_demos([&] { return std::make_unique<ModelPolicy>(model); }, demos, c.world, c.threads);
  return {iteration, 0, rows, t.deviation, t.stats.stacked.value, t.stats.realistic_success.value, t.stats.dice_in_cup_mean};
}

}  // namespace dicestack
