#include <dicestack/experiments/baseline.hpp>

#include <memory>

#include <dicestack/core/error.hpp>
#include <dicestack/core/open_loop.hpp>
#include <dicestack/core/reinforce.hpp>
#include <dicestack/core/rrt.hpp>

namespace dicestack {
namespace {

// The network REINFORCE learned, acting on states.
class NetworkPolicy final : public Policy {
 public:
  NetworkPolicy(std::shared_ptr<const PolicyNetwork> net, const WorldConfig& world) : net_(std::move(net)), world_(world) {}
  Action act(const History& h) override { return net_->act(h.current(), world_); }
  std::string name() const override { return "reinforce"; }

 private:
  std::shared_ptr<const PolicyNetwork> net_;
  WorldConfig world_;
};

PolicyFactory playing(const std::vector<Action>& actions) {
  Episode sequence;
  sequence.actions = actions;
  return [sequence] { return std::make_unique<PlaybackPolicy>(sequence); };
}

PolicyFactory open_loop(const std::string& method, const WorldConfig& world, const Profile& profile, std::uint64_t seed,
                        int threads) {
  OptimiseOptions o;
  o.method = method;
  o.evaluations = o.method == "bayes" ? profile.bayes_evaluations : profile.optimiser_evaluations;
  o.seed = seed;
  OpenLoopProblem problem(world, {}, threads);
  return playing(problem.actions(optimise(problem, o).best.data()));
}

PolicyFactory rrt_baseline(const WorldConfig& world, const Profile& profile, std::uint64_t seed, int threads) {
  RrtOptions o;
  o.nodes = profile.rrt_nodes;
  o.seed = seed;
  o.threads = threads;
  return playing(rrt(world, o).actions);
}

PolicyFactory reinforce_baseline(const WorldConfig& world, const Profile& profile, std::uint64_t seed, int threads) {
  ReinforceOptions o;
  o.iterations = profile.reinforce_iterations;
  o.seed = seed;
  o.threads = threads;
  auto net = std::make_shared<const PolicyNetwork>(reinforce(world, o).policy);
  return [net, world] { return std::make_unique<NetworkPolicy>(net, world); };
}

std::vector<BaselineInfo> make_baselines() {
  std::vector<BaselineInfo> all;
  for (const auto& method : optimiser_names())  // every open-loop optimiser is a baseline
    all.push_back({method, "open-loop action sequence optimised by " + method, method == "bayes" ? 60.0 : 30.0,
                   [method](const Profile& p) { return method == "bayes" ? p.bayes_evaluations : p.optimiser_evaluations; },
                   [method](const WorldConfig& w, const Profile& p, std::uint64_t seed, int threads) {
                     return open_loop(method, w, p, seed, threads);
                   }});
  all.push_back({"reinforce", "REINFORCE policy network, from rewards alone", 40.0,
                 [](const Profile& p) { return p.reinforce_iterations; }, &reinforce_baseline});
  all.push_back({"rrt", "RRT over world snapshots, its best branch played open loop", 20.0,
                 [](const Profile& p) { return p.rrt_nodes; }, &rrt_baseline});
  return all;
}

}  // namespace

const std::vector<BaselineInfo>& baselines() {
  static const std::vector<BaselineInfo> all = make_baselines();
  return all;
}

const BaselineInfo& baseline(const std::string& name) {
  for (const auto& b : baselines())
    if (b.name == name) return b;
  std::string list;
  for (const auto& b : baselines()) list += b.name + ", ";
  throw ConfigError("unknown baseline \"" + name + "\"; expected " + list.substr(0, list.size() - 2) + " or all");
}

std::vector<std::string> baseline_names() {
  std::vector<std::string> out;
  for (const auto& b : baselines()) out.push_back(b.name);
  return out;
}

}  // namespace dicestack
