#pragma once
// One search over action sequences for every optimiser in dicestack: the open-loop baselines
// (open_loop.hpp), the RRT's extensions (rrt.hpp) and DaD's corrections (learners/corrector.hpp)
// are cost functions over it, and each can use every method: CMA-ES (ours), differential
// evolution (pagmo), basin hopping (Metropolis + NLopt's COBYLA) and Bayesian optimisation.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/env.hpp>

namespace dicestack {

/// Where a search moves: x, with action k of step t = clip(x[3t + k]) * world.action.scale[k].
enum class ActionBox {
  unit,    ///< each x in [-1, 1]: the actions the baselines explore
  limits,  ///< each x within action.limit / action.scale: every action the world accepts
};

/// What is minimised: `steps` actions, scored by `cost` (lower is better). The cost function
/// puts the scratch environment it is given where the sequence starts (restores a snapshot, or
/// resets to a state with a noise seed) and runs the actions.
class ActionSequenceProblem {
 public:
  using Cost = std::function<double(DiceEnv& env, const std::vector<Action>& actions)>;

  /// Throws ConfigError unless steps >= 1.
  ActionSequenceProblem(const WorldConfig& world, int steps, ActionBox box, Cost cost);

  std::size_t dim() const { return static_cast<std::size_t>(steps_) * kActionDim; }
  int steps() const { return steps_; }
  /// The box's half-width in coordinate i.
  double bound(std::size_t i) const;
  double clip(std::size_t i, double v) const;
  /// x clipped to the box, in the world's units.
  std::vector<Action> actions(const double* x) const;
  /// The point of `actions` (steps() of them), clipped to the box.
  Eigen::VectorXd point(const std::vector<Action>& actions) const;
  double cost(DiceEnv& env, const double* x) const { return cost_(env, actions(x)); }

 private:
  std::array<double, kActionDim> scale_, half_width_;
  int steps_;
  Cost cost_;
};

/// The scratch worlds a search evaluates in, and its count of evaluations: one environment
/// (every evaluation on the calling thread), or a pool whose environments evaluate a CMA-ES
/// generation in parallel, dealt among the ranks of `cluster` too (then every rank runs the
/// same search and calls the same methods in the same order). Results do not depend on which,
/// nor on the thread or rank count.
class SequenceEvaluator {
 public:
  explicit SequenceEvaluator(DiceEnv& env) : env_(&env) {}
  /// `threads` as parallel_for takes it; `pool` must hold that many environments.
  SequenceEvaluator(EnvPool& pool, int threads, Cluster& cluster = local_cluster())
      : pool_(&pool), threads_(threads), cluster_(&cluster) {}

  double cost(const ActionSequenceProblem& problem, const double* x);
  /// Every row of `xs` (one candidate per row).
  std::vector<double> costs(const ActionSequenceProblem& problem, const Eigen::MatrixXd& xs);
  int evaluations() const { return evaluations_; }

 private:
  DiceEnv& first();

  DiceEnv* env_ = nullptr;
  EnvPool* pool_ = nullptr;
  int threads_ = 1;
  Cluster* cluster_ = nullptr;
  int evaluations_ = 0;
};

struct MinimiseOptions {
  std::string method = "cmaes";  ///< minimiser_names()
  /// Budget in cost evaluations; 0: `iterations` decides. CMA-ES stops once it is spent (its
  /// last generation may pass it); DE runs whole generations while one still fits.
  int evaluations = 0;
  /// Generations of CMA-ES and DE; basin hopping and Bayesian optimisation, which have none,
  /// get iterations x population evaluations. Used when `evaluations` is 0.
  int iterations = 0;
  int population = 0;     ///< CMA-ES's lambda, DE's size; 0: 4 + floor(3 ln n) (DE: at least 5)
  double sigma0 = 0.25;   ///< CMA-ES's initial step, DE's initial spread around x0, COBYLA's step
  /// Where the search starts (clipped to the box); empty: 0, the cup left alone. DE seeds its
  /// population with x0 and a Gaussian cloud of sigma0 around it; without x0, uniformly in the box.
  std::optional<Eigen::VectorXd> x0;
  std::uint64_t seed = 0;
};

struct MinimiseResult {
  Eigen::VectorXd best;        ///< the best point evaluated, inside the box
  double best_cost = 0.0;
  int evaluations = 0;         ///< cost evaluations this search made
  std::vector<std::pair<int, double>> curve;  ///< (evaluations so far, best cost so far), per generation or local search
};

/// The methods minimise() accepts: cmaes, de, basinhop, bayes.
std::vector<std::string> minimiser_names();

/// Minimises `problem`, evaluating in `evaluator`. `progress` (may be empty) gets the
/// evaluations done and the best cost so far after each generation. Deterministic for a seed.
/// Throws ConfigError for an unknown method or a budget of neither evaluations nor iterations.
MinimiseResult minimise(const ActionSequenceProblem& problem, SequenceEvaluator& evaluator, const MinimiseOptions& options,
                        const std::function<void(int evaluations, double best)>& progress = {});

}  // namespace dicestack
