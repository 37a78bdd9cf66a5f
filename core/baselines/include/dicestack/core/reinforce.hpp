#pragma once
// The paper's REINFORCE baseline (Section V-C): a Gaussian policy on a 3-layer network learns
// from the reward minus the state distance to the goal stack, from the paper's start.
#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/env.hpp>

namespace dicestack {

struct ReinforceOptions {
  int iterations = 200;        ///< policy updates
  int batch = 8;               ///< episodes per update (rolled out in parallel)
  int steps = 50;              ///< control steps per episode
  int hidden = 32;             ///< units per hidden layer (paper: 32)
  double leak = 0.05;          ///< LeakyReLU slope (paper: 0.05)
  double sigma = 0.3;          ///< std of the Gaussian exploration, in scaled action units (paper: 0.3)
  double discount = 0.99;      ///< return discount (paper: 0.99)
  double baseline_decay = 0.99;///< per-timestep moving-average baseline, b_t <- a b_t + (1 - a) G_t (paper: 0.99)
  double learning_rate = 1e-3; ///< Adam
  std::uint64_t seed = 0;
  int threads = 0;
  /// The ranks that share each batch's episodes (dealt round-robin, gathered in index order):
  /// every rank computes the same update (docs/scaling.md).
  Cluster* cluster = &local_cluster();
};

/// The policy network: state / cost.sigma -> LeakyReLU -> LeakyReLU -> tanh, times the action scale.
class PolicyNetwork {
 public:
  PolicyNetwork(int hidden, double leak, std::uint64_t seed);
  /// The mean action in scaled units ([-1, 1]^3) for a state already divided by the scales.
  Eigen::Vector3d mean(const Eigen::VectorXd& x) const;
  /// The mean action for a raw state of `world` (the policy's greedy action, in world units).
  Action act(const State& state, const WorldConfig& world) const;
  /// Adds d log N(a; mean(x), sigma^2) / d parameters, times `weight`, to `grad` (same layout as params()).
  void accumulate_gradient(const Eigen::VectorXd& x, const Eigen::Vector3d& a, double sigma, double weight,
                           Eigen::VectorXd& grad) const;
  Eigen::VectorXd params() const;
  void set_params(const Eigen::VectorXd& p);
  Eigen::Index size() const;

 private:
  // The parameter blocks in params()'s order.
  template <class Self, class F>
  static void blocks(Self& self, F&& f) {
    f(self.w1_), f(self.b1_), f(self.w2_), f(self.b2_), f(self.w3_), f(self.b3_);
  }

  Eigen::MatrixXd w1_, w2_, w3_;
  Eigen::VectorXd b1_, b2_, b3_;
  double leak_;
};

struct ReinforcePoint {
  int iteration = 0;
  double mean_return = 0.0;   ///< undiscounted sum of rewards, mean over the batch
  double greedy_cost = 0.0;   ///< eq. 6 cost of the mean-action rollout after the update
};

struct ReinforceResult {
  PolicyNetwork policy;
  std::vector<ReinforcePoint> curve;
  std::vector<Action> greedy_actions;  ///< the final policy's mean actions from the paper's start
  double seconds = 0.0;
};

/// Trains from the paper's start; deterministic for a seed whatever the thread count.
/// Throws ConfigError for bad options.
ReinforceResult reinforce(const WorldConfig& world, const ReinforceOptions& options,
                          const std::function<void(const ReinforcePoint&)>& progress = {});

}  // namespace dicestack
