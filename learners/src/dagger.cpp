#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <optional>

#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/datasets/episode_bytes.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/policy.hpp>

#include "checkpoint.hpp"

namespace dicestack {
namespace {

// DAgger's options as one run uses them, resolved in one place (dagger_settings): retry from the
// feature map. The model records them as "dagger_settings".
struct DaggerSettings {
  int iterations = 0, rollouts = 0;
  double beta = 0.0;
  bool linear = false;  // the schedule: 1 down to 0, else beta^(i-1)
  std::string expert;
  bool replan = true, retry = false, include_demos = true;

  std::string summary() const {
    char text[256];
    std::snprintf(text, sizeof text, "iterations=%d, rollouts=%d, beta=%g, schedule=%s, expert=%s, replan=%s, retry=%s, include_demos=%s",
                  iterations, rollouts, beta, linear ? "linear" : "exponential", expert.c_str(), replan ? "true" : "false",
                  retry ? "true" : "false", include_demos ? "true" : "false");
    return text;
  }

  // The mixture's expert share in round i (1-based).
  double beta_at(int i) const {
    if (linear) return iterations <= 1 ? 1.0 : 1.0 - static_cast<double>(i - 1) / (iterations - 1);
    return std::pow(beta, i - 1);
  }
};

DaggerSettings dagger_settings(const Params& params, const std::string& features) {
  DaggerSettings d;
  d.iterations = static_cast<int>(params.integer("iterations"));
  d.rollouts = static_cast<int>(params.integer("rollouts"));
  d.beta = params.real("beta");
  d.linear = params.choice("schedule") == "linear";
  d.expert = params.choice("expert");
  d.replan = params.boolean("replan");
  d.retry = expert_retries(params.choice("retry"), features);
  d.include_demos = params.boolean("include_demos");
  return d;
}

// DAgger (Ross et al.): roll out the mixture beta_i * expert + (1 - beta_i) * learner from
// random starts, label every visited state with the expert's action, aggregate, refit.
class Dagger final : public Learner {
 public:
  using Learner::Learner;

  LearnResult learn(const LearnContext& c) const override {
    const TrainingPerturbation perturbation = learner_perturbation(params(), c.world, "dagger");  // before any work
    require_labellable(perturbation, feature_map(c.features), "dagger", true);
    require_learnable_map("dagger", params(), feature_map(c.features));
    const DaggerSettings d = dagger_settings(params(), c.features);
    const int iterations = d.iterations, rollouts = d.rollouts;
    const std::string& expert_name = d.expert;
    ExpertConfig expert_config = learner_expert_config(expert_name, *this, c);
    // Without replanning, mpc's labels are a function of the start, the step and the state: the
    // same on and off its own path (docs/learners.md).
    expert_config.replan = d.replan;
    expert_config.retry = d.retry;
    std::vector<Episode> data = d.include_demos ? c.demos : std::vector<Episode>{};
    std::shared_ptr<Model> model;
    LearnResult result;
    int first = 1;
    if (const auto state = load_checkpoint_state(c, "dagger.json", run_settings(c, effective_options(*this), extendable()))) {
      first = state->iteration() + 1;
      data = state->data();
      result.curve = state->curve();
    }
    if (!data.empty()) model = fit_model(c, data, derive_seed(c.seed, static_cast<std::uint64_t>(first - 1)));

    const auto workers = static_cast<std::size_t>(resolve_threads(c.threads));
    EnvPool envs(c.world, c.threads);
    std::vector<std::unique_ptr<Expert>> experts(workers);
    for (int i = first; i <= iterations; ++i) {
      const double beta = d.beta_at(i);
      std::atomic<int> finished{0};
      const int ranks = c.cluster->size();
      // Dealt among the ranks, gathered in index order on every rank.
      std::vector<Episode> fresh = distributed_map<Episode>(
          *c.cluster, static_cast<std::size_t>(rollouts), c.threads,
          [&](std::size_t k, int w) {
            auto& expert = experts[static_cast<std::size_t>(w)];
            if (!expert) expert = make_expert(expert_name, expert_config);
            Episode e = mixture_rollout(envs.at(w), *expert, model.get(), beta,
                                        training_start_seed(derive_seed(c.seed, static_cast<std::uint64_t>(i)), k),
                                        perturbation.trained);
            const int done = std::min(rollouts, ++finished * ranks);
            if (c.progress && w == 0)  // one thread reports
              c.progress({"rollouts", i, iterations, 0, 0, done, rollouts, (i - 1 + static_cast<double>(done) / rollouts) / iterations});
            return e;
          },
          [](const Episode& e) { return episode_to_bytes(e); }, [](std::string_view b) { return episode_from_bytes(b); });
      for (auto& e : fresh) data.push_back(std::move(e));
      if (c.progress) c.progress({"fit", i, iterations, 0, 0, 0, 1, static_cast<double>(i) / iterations});
      model = fit_model(c, data, derive_seed(c.seed, static_cast<std::uint64_t>(i)));
      std::size_t rows = 0;
      for (const auto& e : data) rows += e.size();
      result.curve.push_back(measure_policy(model, c, c.demos, i, rows));
      if (!c.checkpoint_dir.empty() && c.cluster->is_root())
        save_checkpoint(c.checkpoint_dir, i,
                        {{"run", run_settings(c, effective_options(*this), extendable())}, {"seed", c.seed}, {"regressor", c.regressor}, {"beta", beta}, {"curve", curve_to_json(result.curve)}},
                        "dagger.json", c, data, "DAgger aggregate after round " + std::to_string(i));
    }
    if (!model) throw InputError("dagger: no data (no demonstrations and no iterations)");
    model->record["learner"] = "dagger";
    model->record["expert"] = expert_name;
    model->record["dagger_settings"] = d.summary();  // the options as this run used them
    if (expert_config.recordings) {
      model->record["tracker_followed"] = followed_recordings(*expert_config.recordings);
      model->record["tracker_settings"] = tracker_summary(expert_config.recordings->config());
    }
    record_perturbation(perturbation, *model);
    result.model = model;
    return result;
  }

  static std::vector<ParamSpec> schema() {
    std::vector<std::string> names;
    for (const auto& e : expert_list()) names.push_back(e.name);
    std::vector<ParamSpec> specs{{"iterations", ParamType::integer, "5", 0, 1000, "DAgger rounds", {}},
            {"rollouts", ParamType::integer, "20", 1, 100000, "mixture rollouts per round, from random starts", {}},
            {"beta", ParamType::real, "0.5", 0, 1, "p of the exponential schedule beta_i = p^(i-1)", {}},
            {"schedule", ParamType::choice, "exponential", 0, 0, "exponential (p^(i-1)) or linear (1 down to 0)", {"exponential", "linear"}},
            {"expert", ParamType::choice, "mpc", 0, 0, "the expert that acts and labels (tracker: follows the recordings of --demos)", names},
            {"replan", ParamType::boolean, "true", 0, 1, "mpc: replan when the world leaves its prediction", {}},
            retry_param_spec(),
            {"include_demos", ParamType::boolean, "true", 0, 1, "start the aggregate from the demonstrations", {}}};
    for (auto& p : tracker_param_specs()) specs.push_back(std::move(p));
    for (auto& p : perturb_param_specs()) specs.push_back(std::move(p));
    return specs;
  }

 private:
  // More rounds continue the same run under the exponential schedule (beta_i does not depend
  // on the round count); the linear schedule's betas do.
  std::vector<std::string> extendable() const {
    return params().choice("schedule") == "exponential" ? std::vector<std::string>{"iterations"} : std::vector<std::string>{};
  }

  // One episode of the mixture policy, in the world `perturbation` draws for it; every visited
  // state is labelled with the expert's action. A step's source says who acted: the expert, or
  // the learner ("policy").
  static Episode mixture_rollout(DiceEnv& pooled, Expert& expert, const Model* model, double beta, std::uint64_t seed,
                                 const Perturbation& perturbation) {
    PerturbedEnv episode(pooled, perturbation, seed, expert.controller());
    MixturePolicy mixture(expert, episode.env(), model, beta);
    Episode e = rollout(episode, mixture, episode.random_start(seed), seed, StepSource::policy);
    e.origin = "dagger";
    return e;
  }

  // beta * expert + (1 - beta) * learner: a seeded coin per step chooses who acts; the expert
  // is asked every step and its action is the label either way.
  class MixturePolicy final : public Policy {
   public:
    MixturePolicy(Expert& expert, const DiceEnv& env, const Model* model, double beta)
        : expert_(expert, env), model_(model), beta_(beta) {}
    void attach(const DiceEnv& env) override { expert_.attach(env); }
    void reset(std::uint64_t seed) override {
      expert_.reset(seed);
      coin_ = Rng(derive_seed(seed, 7));
    }
    Action act(const History& h) override {
      label_.label = expert_.act(h);
      const bool expert_acts = model_ == nullptr || coin_.uniform() < beta_;
      label_.source = expert_acts ? StepSource::expert : StepSource::policy;
      return expert_acts ? label_.label : model_->act(h);
    }
    std::optional<Labelled> label() const override { return label_; }
    std::string name() const override { return "dagger"; }

   private:
    ExpertPolicy expert_;
    const Model* model_;
    double beta_;
    Rng coin_{0};
    Labelled label_;
  };
};

}  // namespace

void register_dagger(LearnerRegistry& r) {
  r.add({"dagger", "DAgger: mixture rollouts labelled by an automatic expert, aggregated and refitted", Dagger::schema(),
         [](std::string n, Params p) { return std::make_unique<Dagger>(std::move(n), std::move(p)); }});
}

}  // namespace dicestack
