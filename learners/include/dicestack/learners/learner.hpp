#pragma once
// The Learner interface and its registry: a learner turns demonstrations and a regressor into
// a trained Model. Learners are created by name with "key=value" options, like regressors.
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/regressors/model.hpp>

namespace dicestack {

/// Where a learner stands, for progress bars.
struct Progress {
  std::string phase;    ///< e.g. "fit", "rollouts", "corrections"
  int iteration = 0;    ///< 1-based, of `iterations`; both 0 for work before the iterations (the tracker's paths)
  int iterations = 0;
  int window = 0;       ///< DaD: 1-based window of `windows` (0 for other learners)
  int windows = 0;
  int done = 0;         ///< work items finished in this phase
  int total = 0;
  double fraction = 0.0;  ///< of the whole run's work, in [0, 1], for an estimate of the time left
};

/// A progress line's text: "dart gbt: iteration 1/1, demonstrations 3/20", with DaD's window,
/// and without an iteration for work before the iterations. `who` names the run ("dart gbt").
std::string progress_text(const std::string& who, const Progress& p);

/// The seconds a job has left at `fraction` done, timed from when it stood at `counted_from`
/// (`seconds` ago): the first fraction above 0 a bar saw, since work shown at 0 % before it (the
/// tracker preparing its paths) has no known share of the job. Negative when the fraction has not
/// moved a hundredth since: too little to tell.
double time_left(double seconds, double fraction, double counted_from);

/// One point of a learning curve: the policy after an iteration, rolled out from the
/// evaluation demonstrations' first states (the held-out ones when there are any).
struct CurvePoint {
  int iteration = 0;
  int window = 0;               ///< DaD's window (0 for other learners)
  std::size_t dataset_rows = 0; ///< rows the policy was fitted on
  double deviation = 0.0;       ///< mean over steps of the scaled distance to the demonstration
  double stacked_rate = 0.0;
  double realistic_success_rate = 0.0;
  double dice_in_cup_mean = 0.0;
};

/// Writes a learning curve as CSV (one header row, one row per point), atomically.
void write_curve_csv(const std::vector<CurvePoint>& curve, const std::filesystem::path& path);

/// Everything a learner needs.
struct LearnContext {
  std::vector<Episode> demos;  ///< training demonstrations
  std::vector<Episode> held_out;  ///< demonstrations not trained on, to measure and select policies; may be empty
  WorldConfig world;
  std::string regressor = "knn";
  std::vector<std::string> regressor_sets;  ///< "key=value" for the regressor
  std::string features = "state";           ///< the feature map every fitted model reads (features.hpp)
  std::uint64_t seed = 0;
  int threads = 0;                           ///< 0 = all cores
  const RegressorRegistry* registry = &RegressorRegistry::global();
  std::function<void(const Progress&)> progress;  ///< may be empty
  std::filesystem::path checkpoint_dir;      ///< empty: no checkpoints
  bool resume = false;                       ///< continue from checkpoint_dir's last iteration
  /// The ranks that share the work: rollouts and corrections are dealt among them,
  /// the root refits and broadcasts the model, only the root writes checkpoints. Every rank runs
  /// learn() with the same context; the result is the same on each and for any number of ranks.
  Cluster* cluster = &local_cluster();
};

struct LearnResult {
  std::shared_ptr<Model> model;
  std::vector<CurvePoint> curve;  ///< one point per iteration (empty for one-shot learners)
};

class Learner {
 public:
  Learner(std::string name, Params params) : name_(std::move(name)), params_(std::move(params)) {}
  virtual ~Learner() = default;
  const std::string& name() const { return name_; }
  const Params& params() const { return params_; }
  /// Whether the option `key` was given (not left at its default): settings given on top of a
  /// preset override it, the others follow it (tracker_preset).
  bool given(std::string_view key) const;
  /// The keys given, as LearnerRegistry::create sets them from its assignments.
  void set_given(std::vector<std::string> keys) { given_ = std::move(keys); }
  /// Throws InputError if there are no demonstrations, ConfigError for a bad regressor.
  virtual LearnResult learn(const LearnContext& context) const = 0;
  /// The feature map this learner, with its options, reads when none is named; empty: its
  /// registry default (LearnerInfo::default_features). See default_features().
  virtual std::string preferred_features() const { return {}; }

 private:
  std::string name_;
  Params params_;
  std::vector<std::string> given_;
};

struct LearnerInfo {
  std::string name;
  std::string description;
  std::vector<ParamSpec> params;
  std::function<std::unique_ptr<Learner>(std::string, Params)> factory;
  bool needs_trajectories = false;  ///< learns from whole episodes, so not from shuffled rows
  std::string default_features = "state";  ///< the feature map used when none is named (docs/learners.md)
  /// A leaderboard adds no map to its own (--features and the paper profile's extra maps skip it:
  /// DaD's rows take minutes each).
  bool own_features_only = false;
};

/// Learners by name ("bc", "dagger", "dad", "dart"); built-ins registered on first use.
class LearnerRegistry {
 public:
  static LearnerRegistry& global();
  /// Throws ConfigError if the name is taken.
  void add(LearnerInfo info);
  /// Throws ConfigError for an unknown name (listing the registered ones) or bad options.
  std::unique_ptr<Learner> create(std::string_view name, const std::vector<std::string>& assignments = {}) const;
  const LearnerInfo& info(std::string_view name) const;
  std::vector<std::string> names() const;

 private:
  std::map<std::string, LearnerInfo, std::less<>> entries_;
};

/// A learner with options of its own, as a leaderboard row names it: "NAME" or
/// "NAME:key=value[:key=value...]", e.g. "dart:expert=tracker" (DART from the recordings alone).
struct LearnerSpec {
  std::string text;                  ///< as given: the row's name
  std::string name;                  ///< the registered learner
  std::vector<std::string> options;  ///< "key=value", checked against the learner's schema
};

/// Parses and checks a spec against the registry (unknown learner, option or value: ConfigError,
/// naming the spec).
LearnerSpec parse_learner_spec(std::string_view text, const LearnerRegistry& registry = LearnerRegistry::global());

/// The feature map a learner with these options reads when none is named: its registry default,
/// unless its options call for another (dart labelled by the tracker answers cup velocities).
/// Throws ConfigError as LearnerRegistry::create.
std::string default_features(std::string_view learner, const std::vector<std::string>& options = {});

/// Fits `context.regressor` on every step of `data`, each seen through `context.features`:
/// behaviour cloning's one step. Collective over context.cluster: the root fits, the others
/// receive its model file's bytes (so every rank acts with the very same model).
/// `rows`: only the steps it keeps are rows (make_dataset).
std::shared_ptr<Model> fit_model(const LearnContext& context, const std::vector<Episode>& data, std::uint64_t seed,
                                 const RowFilter& rows = {});

/// The `perturb` and `estimator` options of the learners that record episodes (DART, DAgger):
/// domain randomisation, each training episode in its own world drawn from its seed (LEVEL or
/// FILE), and what stands between the sensors and the policy.
std::vector<ParamSpec> perturb_param_specs();

/// How a learner's episodes are perturbed, and what the policy will run behind.
struct TrainingPerturbation {
  /// The draws the training episodes run in.
  Perturbation trained;
  /// "none", or the estimator the policy is to run behind (the model names it, and evaluation
  /// uses it unless told otherwise). With an estimator, the perturbation's sensing factors and
  /// delays are left out of training: the estimator shows the policy the state its action lands
  /// in, so the policy is trained on the state and the expert labels it (a label then depends on
  /// nothing the policy does not see).
  std::string estimator = "none";
  /// The option as given, for the model's record ("none": nominal).
  std::string name = "none";
};
/// Those options, checked against `world`; throws ConfigError naming the option.
TrainingPerturbation learner_perturbation(const Params& params, const WorldConfig& world, const std::string& learner);
/// Throws ConfigError naming the first factor of `p.trained` the expert cannot label for a
/// policy on `features`: its labels answer the world's own state, so they must be a function of
/// what the policy is shown. Observation noise never is (behind no estimator the policy sees
/// noise the label ignores); a delay is only on an "/ahead" or "/landing" map, whose row carries
/// what is pending and unseen, and an observation delay drawn per episode not even there (the
/// row does not say how old its state is). A learner whose rollouts run its own choices
/// (`own_choices`: DAgger) records only the expert's labels of them, so no row can rebuild what
/// was pending under a delay: every delay is refused.
void require_labellable(const TrainingPerturbation& p, const FeatureMap& features, const std::string& learner,
                        bool own_choices = false);
/// Throws ConfigError unless `learner` (with `params`) can learn a policy on `map` when the map
/// reads the arm's links or answers joint torques: bc, on episodes recorded on the arm (the
/// dataset refuses any other by name), or dart and dagger, whose experts run on the arm (human
/// recordings hold neither links nor torques), without include_demos, in the nominal world.
void require_learnable_map(const std::string& learner, const Params& params, const FeatureMap& map);
/// The same for a learner's options (a leaderboard's row): a map of the arm's links or torques
/// as require_learnable_map says, else nothing when `schema` has no "perturb".
void require_labellable(const std::vector<ParamSpec>& schema, const Params& params, const WorldConfig& world,
                        const FeatureMap& features, const std::string& learner);
/// Names `p` in the model's record: "perturb", and "estimator" when the policy runs behind one.
void record_perturbation(const TrainingPerturbation& p, Model& model);

}  // namespace dicestack
