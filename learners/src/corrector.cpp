#include <dicestack/learners/corrector.hpp>

#include <algorithm>

#include <dicestack/core/action_sequence.hpp>
#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/core/tracker.hpp>

namespace dicestack {

double window_cost(DiceEnv& env, const CorrectionProblem& problem, const std::vector<Action>& actions,
                   std::vector<State>* states, std::vector<ArmLinks>* links) {
  env.restore(problem.start);
  if (states) states->clear();
  if (links) links->clear();
  const bool arm = env.config().embodiment == Embodiment::arm;
  double cost = 0.0;
  const CostConfig& c = env.config().cost;
  for (std::size_t j = 0; j < problem.target.size(); ++j) {
    if (states) states->push_back(env.get_state());
    if (links && arm) links->push_back(env.world().arm_links());
    env.step(actions[j]);
    const State now = env.get_state();
    switch (problem.aim) {
      case CorrectionTarget::cup: cost += cup_distance_sq(now, problem.target[j], c); break;
      case CorrectionTarget::state: cost += tracking_distance_sq(now, problem.target[j], c); break;
      case CorrectionTarget::dice: {
        const double d = state_distance(now, problem.target[j], c);
        cost += d * d;
        break;
      }
    }
  }
  return cost;
}

namespace {

constexpr std::uint64_t kRandomStartStream = 0x78307374617274ULL;  // "x0start"

// Any method of action_sequence.hpp over the window's actions, in the scaled box of every action
// the world accepts, started from the policy's own actions; the warm start stays the answer
// unless the search finds better.
class SequenceCorrector final : public Corrector {
 public:
  SequenceCorrector(std::string method, const CorrectorOptions& o) : method_(std::move(method)), options_(o) {}

  Correction correct(DiceEnv& env, const CorrectionProblem& p, std::uint64_t seed) const override {
    if (p.action_kind != ActionKind::cup)
      throw InputError("corrector " + method_ + ": a window in joint torques is corrected by track alone");
    const ActionSequenceProblem window(env.config(), static_cast<int>(p.target.size()), ActionBox::limits,
                                       [&p](DiceEnv& e, const std::vector<Action>& actions) { return window_cost(e, p, actions); });
    const Eigen::VectorXd warm = window.point(p.warm);
    Correction c;
    c.actions = window.actions(warm.data());
    c.warm_cost = window_cost(env, p, c.actions);
    MinimiseOptions o;
    o.method = method_;
    o.iterations = options_.iterations;
    o.evaluations = options_.evaluations;
    o.population = options_.population;
    o.sigma0 = options_.sigma0;
    o.x0 = warm;
    if (options_.random_start) {
      Rng rng(derive_seed(seed, kRandomStartStream));
      o.x0 = Eigen::VectorXd(window.dim());
      for (Eigen::Index i = 0; i < o.x0->size(); ++i) (*o.x0)[i] = rng.uniform(-1.0, 1.0);
    }
    o.seed = seed;
    SequenceEvaluator evaluator(env);
    const MinimiseResult found = minimise(window, evaluator, o);
    if (options_.random_start || found.best_cost < c.warm_cost) c.actions = window.actions(found.best.data());
    c.cost = window_cost(env, p, c.actions, &c.states, &c.links);  // deterministic: the cost found
    c.evaluations = found.evaluations + 2;               // with the warm start's and this one
    return c;
  }

 private:
  std::string method_;
  CorrectorOptions options_;
};

// The tracker's feedback law (core/tracker.hpp) along the demonstration's own path: from the
// drifted world the cup is steered back onto the recorded cup path; nothing is searched. The
// warm start (the policy's own actions) stays the answer if it follows the path better. In
// joint torques each cup action is told in torques, as the tracker told in them acts.
class TrackCorrector final : public Corrector {
 public:
  explicit TrackCorrector(double gain) : gain_(gain) {}

  Correction correct(DiceEnv& env, const CorrectionProblem& p, std::uint64_t) const override {
    if (p.reference.size() != p.target.size() || p.reference_actions.size() != p.target.size())
      throw InputError("track corrector: the window needs the demonstration's states and actions at its steps");
    Correction c;
    c.warm_cost = window_cost(env, p, p.warm);
    const CupPath path{"window", p.reference, p.reference_actions};
    env.restore(p.start);
    const PathFollower follower(path, {}, p.reference.front(), env.t(), gain_);
    std::vector<Action> actions;
    for (std::size_t j = 0; j < p.target.size(); ++j) {
      const Action cup = follower.act(env.get_state(), env.t());
      actions.push_back(env.step(p.action_kind == ActionKind::cup ? cup : told_in_torques(env, cup)).applied);
    }
    const double cost = window_cost(env, p, actions);
    c.actions = cost < c.warm_cost ? actions : p.warm;
    c.cost = window_cost(env, p, c.actions, &c.states, &c.links);
    c.evaluations = 3;
    return c;
  }

 private:
  double gain_;
};

}  // namespace

std::vector<std::string> corrector_names() {
  auto names = minimiser_names();
  names.push_back("track");
  return names;
}

std::unique_ptr<Corrector> make_corrector(std::string_view name, const CorrectorOptions& options) {
  if (name == "track") return std::make_unique<TrackCorrector>(options.gain);
  const auto names = minimiser_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    std::string list;
    for (const auto& n : corrector_names()) list += (list.empty() ? "" : ", ") + n;
    throw ConfigError("unknown corrector \"" + std::string(name) + "\"; expected one of " + list);
  }
  return std::make_unique<SequenceCorrector>(std::string(name), options);
}

}  // namespace dicestack
