#include <gtest/gtest.h>

#include <cmath>

#include <dicestack/core/error.hpp>
#include <dicestack/core/reinforce.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {
namespace {

double log_density(const PolicyNetwork& net, const Eigen::VectorXd& x, const Eigen::Vector3d& a, double sigma) {
  return -(a - net.mean(x)).squaredNorm() / (2.0 * sigma * sigma);
}

TEST(Reinforce, PolicyGradientMatchesFiniteDifferences) {
  PolicyNetwork net(8, 0.05, 4);
  Rng rng(2);
  Eigen::VectorXd x(24);
  for (auto& v : x) v = rng.normal();
  const Eigen::Vector3d a(0.3, -0.2, 0.5);
  Eigen::VectorXd grad = Eigen::VectorXd::Zero(net.size());
  net.accumulate_gradient(x, a, 0.3, 2.0, grad);
  const Eigen::VectorXd theta = net.params();
  for (Eigen::Index i = 0; i < theta.size(); i += 7) {
    Eigen::VectorXd up = theta, down = theta;
    up[i] += 1e-6;
    down[i] -= 1e-6;
    PolicyNetwork u = net, d = net;
    u.set_params(up);
    d.set_params(down);
    const double numeric = 2.0 * (log_density(u, x, a, 0.3) - log_density(d, x, a, 0.3)) / 2e-6;
    EXPECT_NEAR(grad[i], numeric, 1e-5 * std::max(1.0, std::abs(numeric))) << "parameter " << i;
  }
}

TEST(Reinforce, LearnsDeterministicallyWhateverTheThreads) {
  ReinforceOptions o;
  o.iterations = 4;
  o.batch = 3;
  o.steps = 8;
  o.seed = 6;
  o.threads = 1;
  const ReinforceResult a = reinforce(WorldConfig{}, o);
  o.threads = 2;
  const ReinforceResult b = reinforce(WorldConfig{}, o);
  EXPECT_EQ(a.policy.params(), b.policy.params());
  ASSERT_EQ(a.curve.size(), 4u);
  for (std::size_t k = 0; k < a.curve.size(); ++k) EXPECT_EQ(a.curve[k].greedy_cost, b.curve[k].greedy_cost);
  EXPECT_EQ(a.greedy_actions.size(), 8u);
  o.batch = 0;
  EXPECT_THROW(reinforce(WorldConfig{}, o), ConfigError);
}

}  // namespace
}  // namespace dicestack
