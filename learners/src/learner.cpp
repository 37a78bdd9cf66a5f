#include <dicestack/learners/learner.hpp>

#include <algorithm>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/estimator.hpp>
#include <dicestack/core/registry_lookup.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>

namespace dicestack {

std::string progress_text(const std::string& who, const Progress& p) {
  std::string text = who + ": ";
  if (p.iterations > 0) text += "iteration " + std::to_string(p.iteration) + "/" + std::to_string(p.iterations) + ", ";
  if (p.windows > 0) text += "window " + std::to_string(p.window) + "/" + std::to_string(p.windows) + ", ";
  text += p.phase;
  if (p.total > 0) text += " " + std::to_string(p.done) + "/" + std::to_string(p.total);
  return text;
}

double time_left(double seconds, double fraction, double counted_from) {
  const double counted = fraction - counted_from;
  return counted > 0.01 ? seconds * (1.0 - fraction) / counted : -1.0;
}

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
  auto learner = i.factory(i.name, Params(i.params, assignments, i.name));
  std::vector<std::string> keys;
  for (const auto& a : assignments) keys.push_back(a.substr(0, a.find('=')));
  learner->set_given(std::move(keys));
  return learner;
}

bool Learner::given(std::string_view key) const { return std::find(given_.begin(), given_.end(), key) != given_.end(); }

std::vector<std::string> LearnerRegistry::names() const { return registered_names(entries_); }

LearnerSpec parse_learner_spec(std::string_view text, const LearnerRegistry& registry) {
  LearnerSpec spec;
  spec.text = std::string(text);
  std::size_t colon = text.find(':');
  spec.name = std::string(text.substr(0, colon));
  while (colon != std::string_view::npos) {
    const std::size_t next = text.find(':', colon + 1);
    spec.options.emplace_back(text.substr(colon + 1, next == std::string_view::npos ? next : next - colon - 1));
    colon = next;
  }
  try {
    registry.create(spec.name, spec.options);  // unknown names, keys and values fail here
  } catch (const ConfigError& e) {
    throw ConfigError("learner \"" + spec.text + "\": " + e.what());
  }
  return spec;
}

std::string default_features(std::string_view learner, const std::vector<std::string>& options) {
  const LearnerRegistry& r = LearnerRegistry::global();
  const std::string preferred = r.create(learner, options)->preferred_features();
  return preferred.empty() ? r.info(learner).default_features : preferred;
}

namespace {

std::shared_ptr<Model> fit_here(const LearnContext& c, const std::vector<Episode>& data, std::uint64_t seed,
                                const RowFilter& rows) {
  const FeatureMap& features = feature_map(c.features);
  const Dataset d = make_dataset(data, features, rows);
  auto model = std::make_shared<Model>(
      Model::train(c.registry->create(c.regressor, c.regressor_sets), d.x, d.y, seed, nullptr, features));
  model->record["regressor_params"] = model->regressor().params().summary();
  model->record["rows"] = std::to_string(d.rows());
  model->record["episodes"] = std::to_string(d.episodes());
  model->record["seed"] = std::to_string(seed);
  return model;
}

}  // namespace

std::shared_ptr<Model> fit_model(const LearnContext& c, const std::vector<Episode>& data, std::uint64_t seed,
                                 const RowFilter& rows) {
  if (data.empty()) throw InputError("no demonstrations to learn from");
  if (c.cluster->size() == 1) return fit_here(c, data, seed, rows);
  std::shared_ptr<Model> model;
  const std::string bytes = on_root(*c.cluster, [&] {
    model = fit_here(c, data, seed, rows);
    return model_to_bytes(*model);
  });
  if (!model) model = std::make_shared<Model>(parse_model_file(bytes, "model broadcast by rank 0", *c.registry));
  return model;
}

namespace fs = std::filesystem;

namespace {

constexpr const char* kCurveHeader = "iteration,window,dataset_rows,deviation,stacked_rate,realistic_success_rate,dice_in_cup_mean";

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

std::vector<ParamSpec> perturb_param_specs() {
  std::vector<ParamSpec> specs{
      {"perturb", ParamType::text, "none", 0, 0,
       "domain randomisation: each episode in its own world drawn from its seed (none, easy, medium, hard or a "
       "perturbation file; docs/robustness.md)",
       {}},
      {"estimator", ParamType::choice, "kalman", 0, 0,
       "under perturb's sensing factors and delays: kalman or particle trains without them and the policy runs "
       "behind that estimator (the model names it); none trains through them, refusing a factor the expert cannot "
       "label on the map (observation noise; a delay off an /ahead or /landing map, or drawn per episode for the "
       "observations, or under dagger)",
       estimator_names()}};
  return specs;
}

TrainingPerturbation learner_perturbation(const Params& params, const WorldConfig& world, const std::string& learner) {
  TrainingPerturbation t;
  t.name = params.choice("perturb");
  try {
    t.trained = load_perturbation(t.name, world);
  } catch (const Error& e) {
    throw ConfigError(learner + ": option perturb: " + e.what());
  }
  if (params.choice("estimator") == "none" || !senses(t.trained)) return t;
  t.estimator = params.choice("estimator");
  t.trained.observation_noise = 0.0;
  t.trained.observation_delay = 0;
  t.trained.action_delay = 0;
  t.trained.delays_drawn = false;
  return t;
}

namespace {

// A map whose row holds the step index of the choices made so far, not of the step its action
// lands at ("/landing").
bool reads_choice_clock(const FeatureMap& features) {
  const auto columns = features.column_names();
  return std::find(columns.begin(), columns.end(), "t") != columns.end() && !features.name().ends_with(kLandingSuffix);
}

}  // namespace

void require_labellable(const TrainingPerturbation& p, const FeatureMap& features, const std::string& learner,
                        bool own_choices) {
  const Perturbation& t = p.trained;
  const std::string where = learner + ": option perturb (" + p.name + ") with estimator none: ";
  if (t.observation_noise > 0.0)
    throw ConfigError(where + "observation_noise cannot be labelled: the expert answers the true state and the policy "
                              "would be shown a noisy one; train behind an estimator (estimator=kalman, the default)");
  const char* delayed = t.action_delay > 0 ? "action_delay" : t.observation_delay > 0 ? "observation_delay" : nullptr;
  if (delayed && own_choices)
    throw ConfigError(where + delayed + " cannot be labelled: the rollouts record the expert's labels, not what the "
                              "learner chose, so no row shows what was pending; train behind an estimator "
                              "(estimator=kalman, the default)");
  if (delayed && !features.ahead())
    throw ConfigError(where + delayed + " cannot be labelled on the map " + features.name() +
                      ": the expert answers the state its action lands in, which the row does not show; use an "
                      "\"/ahead\" or \"/landing\" map, or an estimator (estimator=kalman, the default)");
  if (t.action_delay > 0 && t.delays_drawn && reads_choice_clock(features))
    throw ConfigError(where + "a drawn action_delay cannot be labelled on the map " + features.name() +
                      ": its clock counts the choices made, and the label is the reference where the action lands, a "
                      "drawn number of steps later; use the map's \"/landing\" form, whose clock is that step");
  if (t.observation_delay > 0 && t.delays_drawn)
    throw ConfigError(where + "a drawn observation_delay cannot be labelled: the row does not say how old its state is; "
                              "fix the delay (delays_drawn false) or train behind an estimator");
}

void require_learnable_map(const std::string& learner, const Params& params, const FeatureMap& map) {
  if (!map.reads_links() && map.action_kind() == ActionKind::cup) return;
  const std::string what = "learner \"" + learner + "\" on feature map \"" + map.name() + "\"";
  // bc fits the given episodes alone: a set recorded on the arm holds the links and the torques,
  // and the dataset names any episode that does not.
  if (learner == "bc") return;
  // dad's corrections of the policy's own rollouts on the arm: the tracker's targets from training
  // starts, each window steered back by its feedback law (told in torques for a map in them).
  if (learner == "dad") {
    if (params.choice("faithful") != "false")
      throw ConfigError(what + ": faithful= runs the paper's code, which is not built for the arm's links or joint "
                               "torques; leave it at false");
    if (params.choice("starts") != "training")
      throw ConfigError(what + ": dad learns it from the tracker's episodes on the arm: give it starts=training "
                               "(the recordings themselves hold the cup's actions and no links)");
    if (map.action_kind() == ActionKind::joint_torque && params.choice("corrector") != "track")
      throw ConfigError(what + ": dad corrects a window in joint torques by the tracker's feedback law: give it "
                               "corrector=track (a search over torque sequences is not built)");
    return;
  }
  if (learner != "dart" && learner != "dagger")
    throw ConfigError(what + ": a map of the arm's links or joint torques is learned by bc from episodes recorded on the "
                             "arm, or by dart, dagger and dad (starts=training, corrector=track), whose experts run on "
                             "the arm (human recordings hold no links, and the cup's actions)");
  if (params.boolean("include_demos")) throw ConfigError(what + ": include_demos adds recordings without the arm's links");
  if (params.choice("perturb") != "none")
    throw ConfigError(what + ": perturb= is not built for a policy of the arm's links yet; leave it at none");
}

void require_labellable(const std::vector<ParamSpec>& schema, const Params& params, const WorldConfig& world,
                        const FeatureMap& features, const std::string& learner) {
  if (features.reads_links() || features.action_kind() != ActionKind::cup) return require_learnable_map(learner, params, features);
  if (std::none_of(schema.begin(), schema.end(), [](const ParamSpec& s) { return s.name == "perturb"; })) return;
  require_labellable(learner_perturbation(params, world, learner), features, learner, learner == "dagger");
}

void record_perturbation(const TrainingPerturbation& p, Model& model) {
  if (p.trained.nominal() && p.estimator == "none") return;
  model.record["perturb"] = p.name;
  if (p.estimator != "none") model.record["estimator"] = p.estimator;
}

}  // namespace dicestack
