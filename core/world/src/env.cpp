#include <dicestack/core/env.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>

#include "byte_io.hpp"

namespace dicestack {

DiceEnv::DiceEnv(const WorldConfig& config) : world_(config), goal_(goal_state(config)) {}

State DiceEnv::reset(std::uint64_t seed) {
  return reset_to(random_start_state(config(), seed), derive_seed(seed, 1));
}

State DiceEnv::reset_to(const State& state, std::uint64_t seed) {
  world_.set_state(state);
  outcome_ = Outcome{};
  noise_ = Rng(seed);
  return world_.state();
}

StepResult DiceEnv::step(const Action& action) {
  require_finite(action, "action");
  const auto& c = config();
  if (action.kind() == ActionKind::joint_torque && c.embodiment != Embodiment::arm)
    throw InputError("action: joint torques need a world whose embodiment is \"arm\"; in this one the cup floats");
  Action a = action;
  const auto scale = action_scale(c, a.kind()), limit = action_limit(c, a.kind());
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (c.physics.action_noise > 0.0) a[k] += c.physics.action_noise * scale[k] * noise_.normal();
    a[k] = std::clamp(a[k], -limit[k], limit[k]);
  }
  StepResult r = finish_step(world_.step(a));
  r.applied = a;
  return r;
}

double step_reward(const State& observation, int steps, const WorldConfig& config, const State& goal) {
  const int remaining = std::max(0, config.episode.max_steps - steps);
  return -std::pow(config.cost.gamma, remaining) * state_distance(observation, goal, config.cost);
}

StepResult DiceEnv::finish_step(bool wall) {
  const auto& c = config();
  StepResult r;
  r.observation = world_.state();
  observe(outcome_, r.observation, wall, c);
  r.info.t = outcome_.steps;
  r.info.distance = state_distance(r.observation, goal_, c.cost);
  r.info.wall_contact_step = wall;
  r.info.outcome = outcome_;
  r.reward = step_reward(r.observation, outcome_.steps, c, goal_);
  r.terminated = outcome_.realistic_success() && outcome_.stacked_steps >= c.judge.success_hold_steps;
  r.truncated = !r.terminated && outcome_.steps >= c.episode.max_steps;
  return r;
}

EnvSnapshot DiceEnv::snapshot() const { return {world_.snapshot(), outcome_, noise_}; }

void DiceEnv::restore(const EnvSnapshot& snapshot) {
  world_.restore(snapshot.world);
  outcome_ = snapshot.outcome;
  noise_ = snapshot.noise;
}

namespace {

constexpr std::uint32_t kEnvSnapshotMarker = 0x44454e56;  // "DENV"
constexpr std::uint32_t kEnvSnapshotVersion = 1;

}  // namespace

std::string to_bytes(const EnvSnapshot& snapshot) {
  detail::ByteWriter w;
  w.put(kEnvSnapshotMarker);
  w.put(kEnvSnapshotVersion);
  w.put_bytes(snapshot.world.to_bytes());
  const Outcome& o = snapshot.outcome;
  w.put<std::int32_t>(o.steps);
  w.put<std::int32_t>(o.dice_in_cup);
  w.put<std::int32_t>(o.dice_in_cup_now);
  w.put<std::uint8_t>(o.stacked);
  w.put<std::uint8_t>(o.wall_contact);
  w.put<std::int32_t>(o.stacked_steps);
  for (std::uint64_t word : snapshot.noise.words()) w.put(word);
  return w.finish();
}

EnvSnapshot env_snapshot_from_bytes(std::string_view bytes) {
  detail::ByteReader r(bytes, "environment snapshot bytes");
  if (r.get<std::uint32_t>() != kEnvSnapshotMarker) r.fail("not a dicestack environment snapshot (or another byte order)");
  const auto version = r.get<std::uint32_t>();
  if (version != kEnvSnapshotVersion)
    r.fail("version " + std::to_string(version) + ", this dicestack reads " + std::to_string(kEnvSnapshotVersion));
  EnvSnapshot s;
  s.world = WorldSnapshot::from_bytes(r.get_bytes());
  constexpr std::int32_t kMaxInt = std::numeric_limits<std::int32_t>::max();
  const int dice = static_cast<int>(kDiceCount);
  s.outcome.steps = r.get_in<std::int32_t>(0, kMaxInt, "outcome steps");
  s.outcome.dice_in_cup = r.get_in<std::int32_t>(0, dice, "outcome dice_in_cup");
  s.outcome.dice_in_cup_now = r.get_in<std::int32_t>(0, dice, "outcome dice_in_cup_now");
  s.outcome.stacked = r.get_in<std::uint8_t>(0, 1, "outcome stacked") != 0;
  s.outcome.wall_contact = r.get_in<std::uint8_t>(0, 1, "outcome wall_contact") != 0;
  s.outcome.stacked_steps = r.get_in<std::int32_t>(0, kMaxInt, "outcome stacked_steps");
  std::array<std::uint64_t, 4> words{};
  for (auto& word : words) word = r.get<std::uint64_t>();
  s.noise = Rng::from_words(words);
  r.expect_end();
  return s;
}

Box<kStateDim> DiceEnv::observation_space() const {
  const auto& c = config();
  const double inf = std::numeric_limits<double>::infinity();
  const double speed = 2.0 * c.physics.substeps / c.physics.control_dt / c.physics.units_per_metre;
  Box<kStateDim> box;
  const double x_lo = c.walls.left_x + c.walls.radius, x_hi = c.walls.right_x - c.walls.radius;
  const double y_lo = c.walls.floor_y + c.walls.radius, y_hi = c.walls.ceiling_y - c.walls.radius;
  auto body = [&](std::size_t at, std::size_t vat) {
    box.low[at] = x_lo, box.high[at] = x_hi;
    box.low[at + 1] = y_lo, box.high[at + 1] = y_hi;
    box.low[at + 2] = -inf, box.high[at + 2] = inf;
    box.low[vat] = box.low[vat + 1] = -speed;
    box.high[vat] = box.high[vat + 1] = speed;
    box.low[vat + 2] = -inf, box.high[vat + 2] = inf;
  };
  body(state_index::kCupX, state_index::kCupVx);
  for (std::size_t i = 0; i < kDiceCount; ++i) body(state_index::die(i), state_index::die(i) + 3);
  return box;
}

namespace {

template <std::size_t N>
Box<N> within(const std::array<double, N>& limit) {
  Box<N> box;
  for (std::size_t k = 0; k < N; ++k) {
    box.high[k] = limit[k];
    box.low[k] = -limit[k];
  }
  return box;
}

}  // namespace

Box<kActionDim> DiceEnv::action_space() const { return within(config().action.limit); }

Box<kJointCount> DiceEnv::torque_space() const { return within(config().arm.torque_limit); }

EnvPool::EnvPool(const WorldConfig& world, int threads)
    : world_(world), envs_(static_cast<std::size_t>(resolve_threads(threads))) {
  validate(world_);
}

DiceEnv& EnvPool::at(int worker) {
  auto& env = envs_.at(static_cast<std::size_t>(worker));
  if (!env) env.emplace(world_);
  return *env;
}

}  // namespace dicestack
