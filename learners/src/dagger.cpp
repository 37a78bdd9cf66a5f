#include <atomic>
#include <cmath>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/learner.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;

// DAgger (Ross et al.): roll out the mixture beta_i * expert + (1 - beta_i) * learner from
// random starts, label every visited state with the expert's action, aggregate, refit.
class Dagger final : public Learner {
 public:
  using Learner::Learner;

  LearnResult learn(const LearnContext& c) const override {
    const int iterations = static_cast<int>(params().integer("iterations"));
    const int rollouts = static_cast<int>(params().integer("rollouts"));
    const std::string expert_name = params().choice("expert");
    std::vector<Episode> data = params().boolean("include_demos") ? c.demos : std::vector<Episode>{};
    std::shared_ptr<Model> model;
    LearnResult result;
    int first = 1;
    if (c.resume && !c.checkpoint_dir.empty() && fs::exists(c.checkpoint_dir / "dagger.json")) {
      const auto state = nlohmann::json::parse(std::ifstream(c.checkpoint_dir / "dagger.json"));
      first = state.at("iteration").get<int>() + 1;
      data = read_demo_set(c.checkpoint_dir / "data").episodes;
      for (const auto& p : state.at("curve"))
        result.curve.push_back({p.at(0), p.at(1), 0.0, p.at(2), p.at(3), p.at(4)});
    }
    if (!data.empty()) model = fit_model(c, data, derive_seed(c.seed, static_cast<std::uint64_t>(first - 1)));

    const auto workers = static_cast<std::size_t>(resolve_threads(c.threads));
    std::vector<std::optional<DiceEnv>> envs(workers);
    std::vector<std::unique_ptr<Expert>> experts(workers);
    for (int i = first; i <= iterations; ++i) {
      const double beta = beta_at(i, iterations);
      std::vector<Episode> fresh(static_cast<std::size_t>(rollouts));
      std::atomic<int> finished{0};
      parallel_for(fresh.size(), c.threads, [&](std::size_t k, int w) {
        auto& env = envs[static_cast<std::size_t>(w)];
        auto& expert = experts[static_cast<std::size_t>(w)];
        if (!env) env.emplace(c.world);
        if (!expert) expert = make_expert(expert_name);
        fresh[k] = mixture_rollout(*env, *expert, model.get(), beta, derive_seed(derive_seed(c.seed, static_cast<std::uint64_t>(i)), k));
        const int done = ++finished;
        if (c.progress && w == 0) c.progress({"rollouts", i, iterations, done, rollouts});  // one thread reports
      });
      CurvePoint point{i, 0, 0.0, 0.0, 0.0, 0.0};
      for (const auto& e : fresh) {
        point.stacked_rate += e.outcome.stacked / static_cast<double>(rollouts);
        point.realistic_success_rate += e.outcome.realistic_success() / static_cast<double>(rollouts);
        point.dice_in_cup_mean += e.outcome.dice_in_cup / static_cast<double>(rollouts);
      }
      for (auto& e : fresh) data.push_back(std::move(e));
      if (c.progress) c.progress({"fit", i, iterations, 0, 1});
      model = fit_model(c, data, derive_seed(c.seed, static_cast<std::uint64_t>(i)));
      for (const auto& e : data) point.dataset_rows += e.size();
      result.curve.push_back(point);
      if (!c.checkpoint_dir.empty()) save_checkpoint(c, i, data, result.curve, beta);
    }
    if (!model) throw InputError("dagger: no data (no demonstrations and no iterations)");
    model->record["learner"] = "dagger";
    result.model = model;
    return result;
  }

  static std::vector<ParamSpec> schema() {
    std::vector<std::string> names;
    for (const auto& e : expert_list()) names.push_back(e.name);
    return {{"iterations", ParamType::integer, "5", 0, 1000, "DAgger rounds", {}},
            {"rollouts", ParamType::integer, "20", 1, 100000, "mixture rollouts per round, from random starts", {}},
            {"beta", ParamType::real, "0.5", 0, 1, "p of the exponential schedule beta_i = p^(i-1)", {}},
            {"schedule", ParamType::choice, "exponential", 0, 0, "exponential (p^(i-1)) or linear (1 down to 0)", {"exponential", "linear"}},
            {"expert", ParamType::choice, "mpc", 0, 0, "the expert that acts and labels", names},
            {"include_demos", ParamType::boolean, "true", 0, 1, "start the aggregate from the demonstrations", {}}};
  }

 private:
  double beta_at(int i, int iterations) const {
    if (params().choice("schedule") == "linear")
      return iterations <= 1 ? 1.0 : 1.0 - static_cast<double>(i - 1) / (iterations - 1);
    return std::pow(params().real("beta"), i - 1);
  }

  // One episode of the mixture policy; every visited state is labelled with the expert's action.
  // A step's source says who acted: the expert, or the learner ("policy").
  static Episode mixture_rollout(DiceEnv& env, Expert& expert, const Model* model, double beta, std::uint64_t seed) {
    Episode e;
    e.seed = seed;
    e.origin = "dagger";
    env.reset_to(random_start_state(env.config(), seed), seed);
    expert.reset(seed);
    Rng coin(derive_seed(seed, 7));
    while (true) {
      const State s = env.get_state();
      const Action label = expert.act(env);
      const bool expert_acts = model == nullptr || coin.uniform() < beta;
      const Action a = expert_acts ? label : model->act(s);
      e.states.push_back(s);
      e.actions.push_back(label);
      e.sources.push_back(expert_acts ? StepSource::expert : StepSource::policy);
      const StepResult r = env.step(a);
      if (r.terminated || r.truncated) break;
    }
    e.outcome = env.outcome();
    return e;
  }

  // Each round's aggregate is saved whole (so a person could also label between rounds), then
  // the small state file that points at it; a run killed in between resumes from the last one.
  static void save_checkpoint(const LearnContext& c, int i, const std::vector<Episode>& data,
                              const std::vector<CurvePoint>& curve, double beta) {
    fs::create_directories(c.checkpoint_dir);
    DemoSet set;
    set.world = c.world;
    set.description = "DAgger aggregate after round " + std::to_string(i);
    set.provenance = "dicestack dagger, seed " + std::to_string(c.seed) + ", beta " + std::to_string(beta);
    set.episodes = data;
    write_demo_set(set, c.checkpoint_dir / "data");
    nlohmann::json points = nlohmann::json::array();
    for (const auto& p : curve)
      points.push_back({p.iteration, p.dataset_rows, p.stacked_rate, p.realistic_success_rate, p.dice_in_cup_mean});
    AtomicFile f(c.checkpoint_dir / "dagger.json");
    f.stream() << nlohmann::json{{"iteration", i}, {"seed", c.seed}, {"regressor", c.regressor}, {"curve", points}}.dump();
    f.commit();
  }
};

}  // namespace

void register_dagger(LearnerRegistry& r) {
  r.add({"dagger", "DAgger: mixture rollouts labelled by an automatic expert, aggregated and refitted", Dagger::schema(),
         [](std::string n, Params p) { return std::make_unique<Dagger>(std::move(n), std::move(p)); }});
}

}  // namespace dicestack
