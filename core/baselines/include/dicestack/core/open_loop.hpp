#pragma once
// The paper's baselines without demonstrations (Section V-B): optimise an open-loop action
// sequence from the paper's start so that the dice end up in the goal stack, with any of the
// four methods of action_sequence.hpp: CMA-ES (ours), differential evolution (pagmo), basin
// hopping (scipy's Metropolis variant with NLopt's COBYLA as the local minimiser) and Bayesian
// optimisation (a small Gaussian process with expected improvement on Eigen: no packaged C++
// library exists). The cost, eq. 6, is one ActionSequenceProblem.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include <dicestack/core/action_sequence.hpp>
#include <dicestack/core/cluster.hpp>
#include <dicestack/core/env.hpp>

namespace dicestack {

/// What is optimised: x in [-1, 1]^(steps x 3), action k of step t = x[3t + k] * action.scale[k].
struct OpenLoopSettings {
  int steps = 50;         ///< control steps of the sequence (the original used 50; the paper's text 30)
  int repeats = 1;        ///< noisy runs averaged per evaluation (world.physics.action_noise > 0)
  std::uint64_t seed = 0; ///< seeds the noise of the repeats
};

/// Evaluates sequences: eq. 6, sum_j gamma^(T-j) d(s_j, goal) over the states after each step,
/// with gamma = world.cost.gamma. Batches run in parallel, one world per thread; the values do
/// not depend on the thread count.
class OpenLoopProblem {
 public:
  /// Throws ConfigError for a bad world or settings. With several ranks in `cluster`, every rank
  /// makes the same problem and calls the same methods in the same order: cost_batch deals its
  /// rows among the ranks (docs/scaling.md); cost() runs on each rank.
  OpenLoopProblem(const WorldConfig& world, const OpenLoopSettings& settings, int threads = 0,
                  Cluster& cluster = local_cluster());
  OpenLoopProblem(const OpenLoopProblem&) = delete;  // its sequence's cost refers to it
  OpenLoopProblem& operator=(const OpenLoopProblem&) = delete;

  std::size_t dim() const { return static_cast<std::size_t>(settings_.steps) * kActionDim; }
  const WorldConfig& world() const { return world_; }
  std::vector<Action> actions(const double* x) const;
  /// One evaluation on the calling thread's world 0 (for sequential optimisers).
  double cost(const double* x);
  /// Every row of `xs` (lambda x dim), in parallel (collective over the cluster).
  std::vector<double> cost_batch(const Eigen::MatrixXd& xs);
  int evaluations() const;
  /// The problem as minimise() takes it, and the pool it evaluates in.
  const ActionSequenceProblem& sequence() const { return *sequence_; }
  SequenceEvaluator& evaluator() { return *evaluator_; }

 private:
  double run(DiceEnv& env, const std::vector<Action>& actions) const;

  WorldConfig world_;
  OpenLoopSettings settings_;
  State start_, goal_;
  std::optional<EnvPool> envs_;  ///< made once the world is checked and stretched
  std::optional<ActionSequenceProblem> sequence_;
  std::optional<SequenceEvaluator> evaluator_;
};

struct OptimiseOptions {
  std::string method = "cmaes";  ///< minimiser_names(): cmaes, de, basinhop or bayes
  int evaluations = 5000;        ///< budget
  double sigma0 = 0.25;          ///< CMA-ES's initial step, DE's initial spread, basin hopping's step
  std::uint64_t seed = 0;
};

struct OptimiseResult {
  std::vector<double> best;     ///< x of the best evaluated sequence
  double best_cost = 0.0;
  int evaluations = 0;
  double seconds = 0.0;
  std::vector<std::pair<int, double>> curve;  ///< (evaluations so far, best cost so far), per generation
};

/// The names optimise() accepts.
std::vector<std::string> optimiser_names();

/// Minimises `problem` from x = 0 (the cup left alone). `progress` (may be empty) gets the
/// evaluations done and the best cost so far. Throws ConfigError for an unknown method.
OptimiseResult optimise(OpenLoopProblem& problem, const OptimiseOptions& options,
                        const std::function<void(int, double)>& progress = {});

}  // namespace dicestack
