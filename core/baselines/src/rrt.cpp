#include <dicestack/core/rrt.hpp>

#include <algorithm>
#include <chrono>
#include <numbers>
#include <optional>

#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {
namespace {

struct Node {
  EnvSnapshot snapshot;
  State state;
  int parent = -1;
  std::vector<Action> actions;  // from the parent to here
  int depth = 0;                // control steps from the root
};

// A state to grow towards: the goal, or bodies at rest anywhere inside the walls.
State sample_state(const WorldConfig& w, const State& goal, double goal_bias, Rng& rng) {
  if (rng.uniform() < goal_bias) return goal;
  State s{};
  const double left = w.walls.left_x + w.walls.radius, right = w.walls.right_x - w.walls.radius;
  const double table = w.walls.floor_y + w.walls.radius, ceiling = w.walls.ceiling_y - w.walls.radius;
  s[state_index::kCupX] = rng.uniform(left + 1.0, right - 1.0);
  s[state_index::kCupY] = rng.uniform(table + 0.5, ceiling - 1.0);
  s[state_index::kCupAngle] = rng.uniform(-std::numbers::pi, std::numbers::pi);
  for (std::size_t i = 0; i < 3; ++i) {
    s[state_index::die(i)] = rng.uniform(left + 0.5, right - 0.5);
    s[state_index::die(i) + 1] = rng.uniform(table + 0.2, ceiling - 0.5);
    s[state_index::die(i) + 2] = rng.uniform(-std::numbers::pi, std::numbers::pi);
  }
  return s;
}

Action scaled(const double* x, const WorldConfig& w) {
  Action a;
  for (std::size_t k = 0; k < kActionDim; ++k) a[k] = std::clamp(x[k], -1.0, 1.0) * w.action.scale[k];
  return a;
}

}  // namespace

RrtResult rrt(const WorldConfig& config, const RrtOptions& o, const std::function<void(int, double)>& progress) {
  if (o.nodes < 0 || o.extend_steps < 1 || o.extend_iterations < 1 || o.max_depth_steps < 1)
    throw ConfigError("rrt: nodes >= 0, extend_steps, extend_iterations and max_depth_steps >= 1 expected");
  if (!(o.goal_bias >= 0.0 && o.goal_bias <= 1.0)) throw ConfigError("rrt: goal_bias must be in [0, 1]");
  WorldConfig world = config;
  validate(world);
  world.episode.max_steps = std::max(world.episode.max_steps, o.max_depth_steps + o.extend_steps);
  const auto t0 = std::chrono::steady_clock::now();
  const State goal = goal_state(world);
  EnvPool envs(world, o.threads);
  auto env_of = [&](int w) -> DiceEnv& { return envs.at(w); };
  RrtResult result;
  std::vector<Node> tree;
  {
    DiceEnv& env = env_of(0);
    const State s = env.reset_to(paper_start_state(world), 0);
    tree.push_back({env.snapshot(), s, -1, {}, 0});
  }
  std::size_t best = 0;
  double best_d = state_distance(tree[0].state, goal, world.cost);
  Rng rng(o.seed);
  const auto n = static_cast<Eigen::Index>(o.extend_steps * static_cast<int>(kActionDim));
  for (int k = 1; k <= o.nodes; ++k) {
    const State target = sample_state(world, goal, o.goal_bias, rng);
    std::size_t near = tree.size();
    double near_d = 0.0;
    for (std::size_t i = 0; i < tree.size(); ++i) {
      if (tree[i].depth + o.extend_steps > o.max_depth_steps) continue;
      const double d = tracking_distance_sq(tree[i].state, target, world.cost);
      if (near == tree.size() || d < near_d) near = i, near_d = d;
    }
    if (near == tree.size()) break;  // every node is as deep as allowed
    const Node& from = tree[near];
    // Extension: a few steps of actions from the node's exact world, optimised towards the target.
    CmaesOptions co;
    co.sigma0 = 0.5;
    co.max_iterations = o.extend_iterations;
    co.seed = derive_seed(o.seed, static_cast<std::uint64_t>(k));
    Cmaes es(Eigen::VectorXd::Zero(n), co);
    auto final_distance = [&](DiceEnv& env, const double* x) {
      env.restore(from.snapshot);
      for (int t = 0; t < o.extend_steps; ++t) env.step(scaled(x + 3 * t, world));
      return tracking_distance_sq(env.get_state(), target, world.cost);
    };
    while (!es.done()) {
      const Eigen::MatrixXd& xs = es.ask();
      std::vector<double> values(static_cast<std::size_t>(xs.rows()));
      parallel_for(values.size(), o.threads, [&](std::size_t i, int w) {
        const Eigen::VectorXd row = xs.row(static_cast<Eigen::Index>(i)).transpose();
        values[i] = final_distance(env_of(w), row.data());
      });
      result.simulated_steps += static_cast<long long>(values.size()) * o.extend_steps;
      es.tell(values);
    }
    DiceEnv& env = env_of(0);
    env.restore(from.snapshot);
    Node node;
    node.parent = static_cast<int>(near);
    node.depth = from.depth + o.extend_steps;
    for (int t = 0; t < o.extend_steps; ++t) {
      node.actions.push_back(scaled(es.best().data() + 3 * t, world));
      env.step(node.actions.back());
    }
    result.simulated_steps += o.extend_steps;
    node.snapshot = env.snapshot();
    node.state = env.get_state();
    tree.push_back(std::move(node));
    const double d = state_distance(tree.back().state, goal, world.cost);
    if (d < best_d) best = tree.size() - 1, best_d = d;
    if (progress) progress(k, best_d);
  }
  std::vector<std::size_t> path;
  for (int i = static_cast<int>(best); i > 0; i = tree[static_cast<std::size_t>(i)].parent) path.push_back(static_cast<std::size_t>(i));
  for (auto it = path.rbegin(); it != path.rend(); ++it)
    for (const Action& a : tree[*it].actions) result.actions.push_back(a);
  result.best_distance = best_d;
  result.nodes = static_cast<int>(tree.size()) - 1;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace dicestack
