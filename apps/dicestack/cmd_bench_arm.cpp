// `dicestack bench arm`: the arm world's speed beside a bare Box2D loop of the same bodies and
// joints and beside the floating cup, and the joint torques the human recordings' cup paths ask
// of the arm, against its torque limits.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/bare_box2d.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/record.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

namespace si = state_index;

struct ArmBenchOptions {
  WorldOption world;
  std::filesystem::path demos = "human";
  int episodes = 200;
  int steps = 100;
  int repeats = 5;
  bool json = false;
};

// Episodes per second of World::step from the paper's start with random actions (the draws of
// bare_box2d_seconds).
double world_episodes_per_second(const WorldConfig& config, int episodes, int steps) {
  const State start = paper_start_state(config);
  const auto t0 = std::chrono::steady_clock::now();
  for (int e = 0; e < episodes; ++e) {
    World w(config, start);
    Rng rng(derive_seed(1, static_cast<std::uint64_t>(e)));
    for (int t = 0; t < steps; ++t) {
      Action a;
      for (std::size_t k = 0; k < kActionDim; ++k) a[k] = rng.uniform(-1.0, 1.0) * config.action.scale[k];
      w.step(a);
    }
  }
  return episodes / std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// What following the recordings' cup paths asks of each joint: the |torque| of each control
// step's last substep, over every step of every recording, with no torque limit (the demand,
// to set the limits from), and how far the cup strays from the path.
struct Demand {
  std::array<std::vector<double>, 4> torques;
  double position_error = 0.0;  // mean |cup position - recorded|, m
  long long steps = 0;
};

// The arm follows each recording's cup: each action is the velocity change that brings the cup
// to the recorded next velocity, plus a pull towards the recorded next position, as a floating
// cup would take it (gravity's pull over the step made up).
Demand torque_demand(WorldConfig arm, const std::vector<Episode>& recordings) {
  constexpr double kPositionGain = 0.5;  // of the position error made up per step
  arm.arm.torque_limit = {1e7, 1e7, 1e7, 1e7};  // the range's top: only the recordings' stops reach it
  const double dt = arm.physics.control_dt;
  Demand d;
  for (const Episode& e : recordings) {
    World w(arm, e.states.front());
    for (std::size_t t = 0; t + 1 < e.states.size(); ++t) {
      const State& next = e.states[t + 1];
      const State now = w.state();
      Action a{};
      for (std::size_t k = 0; k < kActionDim; ++k) {
        const std::size_t pose = si::kCupX + k, velocity = si::kCupVx + k;
        const double gravity = k == 0 ? arm.physics.gravity.x : k == 1 ? arm.physics.gravity.y : 0.0;
        const double pull = kPositionGain * (next[pose] - now[pose] - now[velocity] * dt) / dt;
        a[k] = next[velocity] - now[velocity] - gravity * dt + pull;
      }
      w.step(a);  // the torques of the last substep stand for the step
      const auto torque = w.arm_joint_torques();
      for (std::size_t j = 0; j < 4; ++j) d.torques[j].push_back(std::abs(torque[j]));
      d.position_error += std::hypot(w.state()[si::kCupX] - next[si::kCupX], w.state()[si::kCupY] - next[si::kCupY]);
      ++d.steps;
    }
  }
  d.position_error /= static_cast<double>(std::max<long long>(d.steps, 1));
  return d;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[static_cast<std::size_t>(std::min<double>(q * static_cast<double>(v.size()), static_cast<double>(v.size() - 1)))];
}

// One joint's line of the demand table.
struct JointDemand {
  const char* joint;
  double p50, p95, p99, largest, limit, within;  // within: the fraction of steps under the limit
};

std::array<JointDemand, 4> demand_rows(const Demand& d, const ArmConfig& arm) {
  const std::array<const char*, 4> names{"shoulder", "elbow", "second elbow", "wrist"};
  std::array<JointDemand, 4> rows{};
  for (std::size_t j = 0; j < 4; ++j) {
    const auto& p = d.torques[j];
    const auto under = std::count_if(p.begin(), p.end(), [&](double v) { return v < arm.torque_limit[j] - 1e-6; });
    rows[j] = {names[j],           quantile(p, 0.5), quantile(p, 0.95), quantile(p, 0.99), quantile(p, 1.0),
               arm.torque_limit[j], static_cast<double>(under) / static_cast<double>(std::max<std::size_t>(p.size(), 1))};
  }
  return rows;
}

int run_arm_bench(const ArmBenchOptions& opt) {
  WorldConfig arm = opt.world.load();
  arm.embodiment = Embodiment::arm;
  validate(arm);
  WorldConfig cup = arm;
  cup.embodiment = Embodiment::cup;
  std::vector<double> held, bare, floating;
  for (int r = 0; r < opt.repeats; ++r) {
    held.push_back(world_episodes_per_second(arm, opt.episodes, opt.steps));
    bare.push_back(opt.episodes / bare_box2d_seconds(arm, opt.episodes, opt.steps, 1));
    floating.push_back(world_episodes_per_second(cup, opt.episodes, opt.steps));
  }
  // The recordings are read in the floating cup's world (their own); the arm follows their cups.
  const auto recordings = read_demo_set(resolve_demo_set(opt.demos, cup)).episodes;
  const Demand d = torque_demand(arm, recordings);
  const auto rows = demand_rows(d, arm.arm);
  if (opt.json) {
    nlohmann::json joints = nlohmann::json::array();
    for (const JointDemand& r : rows)
      joints.push_back({{"joint", r.joint}, {"p50", r.p50}, {"p95", r.p95}, {"p99", r.p99}, {"max", r.largest},
                        {"limit", r.limit}, {"within_limit", r.within}});
    print_line(nlohmann::json{{"arm_episodes_per_second", median(held)},
                              {"bare_episodes_per_second", median(bare)},
                              {"floating_cup_episodes_per_second", median(floating)},
                              {"ratio_to_bare", median(held) / median(bare)},
                              {"recordings", recordings.size()},
                              {"steps", d.steps},
                              {"mean_cup_position_error_m", d.position_error},
                              {"torques", joints}}
                   .dump());
    return 0;
  }
  std::printf("dicestack bench arm: %d episodes x %d control steps, random actions, 1 thread; medians of %d runs\n"
              "  arm world (World::step)        : %7.1f episodes/s (%.3f of bare)\n"
              "  bare Box2D loop, same bodies   : %7.1f episodes/s\n"
              "  floating cup (World::step)     : %7.1f episodes/s\n\n",
              opt.episodes, opt.steps, opt.repeats, median(held), median(held) / median(bare), median(bare), median(floating));
  std::printf("Joint torques the cup paths of %zu recordings ask for (%s; %lld control steps, no torque limit; the cup "
              "within %.3f m of its path on average): |torque| per step, N m, and the steps the world's limits leave "
              "feasible\n\n| joint | median | 95th | 99th | largest | limit | steps within |\n"
              "|---|---:|---:|---:|---:|---:|---:|\n",
              recordings.size(), opt.demos.string().c_str(), d.steps, d.position_error);
  for (const JointDemand& r : rows)
    std::printf("| %s | %.0f | %.0f | %.0f | %.0f | %.0f | %.1f %% |\n", r.joint, r.p50, r.p95, r.p99, r.largest, r.limit,
                100.0 * r.within);
  return 0;
}

}  // namespace

void add_bench_arm_command(CLI::App& bench) {
  auto opt = std::make_shared<ArmBenchOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "arm", "The arm world's speed beside a bare Box2D loop and the floating cup, and the joint torques the recordings' "
             "cup paths ask of it");
  opt->world.add_to(*cmd);
  cmd->add_option("--demos", opt->demos, "The recordings whose cup paths the arm follows (a folder, builtin or human)")
      ->capture_default_str();
  cmd->add_option("--episodes", opt->episodes, "Episodes per speed measurement")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--steps", opt->steps, "Control steps per episode")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--repeats", opt->repeats, "Speed measurements (the median is reported)")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_flag("--json", opt->json, "Print one JSON object");
  cmd->callback([opt] { run_arm_bench(*opt); });
}

}  // namespace dicestack::cli
