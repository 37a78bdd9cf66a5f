#include <dicestack/core/rrt.hpp>

#include <algorithm>
#include <chrono>
#include <numbers>
#include <optional>

#include <dicestack/core/action_sequence.hpp>
#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
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

}  // namespace

RrtResult rrt(const WorldConfig& config, const RrtOptions& o, const std::function<void(int, double)>& progress) {
  if (o.nodes < 0 || o.extend_steps < 1 || o.extend_iterations < 1 || o.max_depth_steps < 1)
    throw ConfigError("rrt: nodes >= 0, extend_steps, extend_iterations and max_depth_steps >= 1 expected");
  if (!(o.goal_bias >= 0.0 && o.goal_bias <= 1.0)) throw ConfigError("rrt: goal_bias must be in [0, 1]");
  const auto names = minimiser_names();
  if (std::find(names.begin(), names.end(), o.method) == names.end())
    throw ConfigError("rrt: unknown method \"" + o.method + "\"; expected cmaes, de, basinhop or bayes");
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
    const ActionSequenceProblem extension(world, o.extend_steps, ActionBox::unit,
                                          [&](DiceEnv& env, const std::vector<Action>& actions) {
                                            env.restore(from.snapshot);
                                            for (const Action& a : actions) env.step(a);
                                            return tracking_distance_sq(env.get_state(), target, world.cost);
                                          });
    MinimiseOptions mo;
    mo.method = o.method;
    mo.sigma0 = 0.5;
    mo.iterations = o.extend_iterations;
    mo.seed = derive_seed(o.seed, static_cast<std::uint64_t>(k));
    SequenceEvaluator evaluator(envs, o.threads, *o.cluster);
    const MinimiseResult found = minimise(extension, evaluator, mo);
    result.simulated_steps += static_cast<long long>(found.evaluations) * o.extend_steps;
    DiceEnv& env = env_of(0);
    env.restore(from.snapshot);
    Node node;
    node.parent = static_cast<int>(near);
    node.depth = from.depth + o.extend_steps;
    node.actions = extension.actions(found.best.data());
    for (const Action& a : node.actions) env.step(a);
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
