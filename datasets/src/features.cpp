#include <dicestack/datasets/features.hpp>

#include <algorithm>
#include <array>
#include <memory>

#include <dicestack/core/error.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {
namespace {

namespace si = state_index;

// What a map shows of the current state: all of it, the cup's six numbers alone (a pattern
// played with feedback on the cup, none on the dice), or nothing (open loop).
enum class Current { state, cup, none };
constexpr std::size_t kCupParts[] = {si::kCupX, si::kCupY, si::kCupAngle, si::kCupVx, si::kCupVy, si::kCupW};

// The built-in maps differ in how much of the current state they show and which blocks follow.
struct Blocks {
  bool clock = false;
  bool start = false;
  bool previous = false;
  bool start_state = false;  // the whole start state instead of its two summary numbers
  Current current = Current::state;
  bool dice_frame = false;  // x measured from the start's mean die x (which one more column holds)
  bool attempts = false;    // the clock and the start restart with each attempt (attempt_start)
};

// The step the current attempt began at, judged in the default world (a map has no world of its
// own; the tracker's retries judge in it too, so both agree).
std::size_t attempt_begin(const History& h) {
  static const WorldConfig nominal{};
  return attempt_start(h.states, nominal);
}

// The state a map's row and answer refer to: for an "/ahead" map the cup where it is when the
// action lands (computed into `scratch`), else the current state itself (no copy: the hot path).
const State& acting_state(const FeatureMap& m, const History& h, State& scratch) {
  return m.ahead() ? (scratch = cup_ahead(h)) : h.current();
}

class BuiltinFeatureMap final : public FeatureMap {
 public:
  BuiltinFeatureMap(std::string name, std::string description, Blocks blocks,
                    ActionTarget target = ActionTarget::impulse, bool ahead = false, bool landing_clock = false)
      : name_(std::move(name)),
        description_(std::move(description)),
        blocks_(blocks),
        target_(target),
        ahead_(ahead),
        landing_clock_(landing_clock) {}

  std::string name() const override { return name_; }
  int version() const override { return 1; }
  std::string description() const override { return description_; }
  ActionTarget target() const override { return target_; }
  bool ahead() const override { return ahead_; }
  bool attempts() const override { return blocks_.attempts; }
  double origin_x(const History& h) const override { return blocks_.dice_frame ? mean_dice_x(start_of(h)) : 0.0; }
  const Blocks& blocks() const { return blocks_; }

  std::size_t width() const override {
    return current_width() + (blocks_.clock ? 1 : 0) + (blocks_.start ? 2 : 0) + (blocks_.previous ? kStateDim : 0) +
           (blocks_.start_state ? kStateDim : 0) + (blocks_.dice_frame ? 1 : 0);
  }

  std::vector<std::string> column_names() const override {
    std::vector<std::string> out;
    if (blocks_.current == Current::state)
      for (auto n : state_names()) out.emplace_back(n);
    if (blocks_.current == Current::cup)
      for (auto k : kCupParts) out.emplace_back(state_names()[k]);
    if (blocks_.clock) out.emplace_back("t");
    if (blocks_.start) out.insert(out.end(), {"start_cup_x", "start_dice_mean_x"});
    if (blocks_.previous)
      for (auto n : state_names()) out.push_back("prev_" + std::string(n));
    if (blocks_.start_state)
      for (auto n : state_names()) out.push_back("start_" + std::string(n));
    if (blocks_.dice_frame) out.emplace_back("origin_x");
    return out;
  }

  void compute(const History& h, std::span<double> out) const override {
    State scratch;
    const State& s = acting_state(*this, h, scratch);
    const std::size_t begin = blocks_.attempts ? attempt_begin(h) : 0;
    const State& start = h.states[begin];
    // Under the dice frame every x is measured from the start's mean die x (that origin last).
    const double x0 = blocks_.dice_frame ? mean_dice_x(start) : 0.0;
    const auto put_state = [&](const State& from, std::size_t at) {
      std::copy(from.begin(), from.end(), out.begin() + static_cast<std::ptrdiff_t>(at));
      if (!blocks_.dice_frame) return;
      out[at + si::kCupX] -= x0;
      for (std::size_t i = 0; i < kDiceCount; ++i) out[at + si::die(i)] -= x0;
    };
    std::size_t at = 0;
    if (blocks_.current == Current::state) put_state(s, 0);
    if (blocks_.current == Current::cup)
      for (auto k : kCupParts) out[at++] = s[k] - (k == si::kCupX ? x0 : 0.0);
    at = current_width();
    if (blocks_.clock) out[at++] = static_cast<double>(h.t() - begin + (landing_clock_ ? h.pending.size() : 0));
    if (blocks_.start) {
      out[at++] = start[si::kCupX] - x0;
      out[at++] = mean_dice_x(start) - x0;
    }
    if (blocks_.previous) {
      put_state(h.states.size() >= 2 ? h.states[h.states.size() - 2] : s, at);
      at += kStateDim;
    }
    if (blocks_.start_state) {
      put_state(start, at);
      at += kStateDim;
    }
    if (blocks_.dice_frame) out[at] = x0;
  }

 private:
  const State& start_of(const History& h) const { return blocks_.attempts ? h.states[attempt_begin(h)] : h.start(); }

  std::size_t current_width() const {
    return blocks_.current == Current::state ? kStateDim : blocks_.current == Current::cup ? std::size(kCupParts) : 0;
  }

  std::string name_, description_;
  Blocks blocks_;
  ActionTarget target_;
  bool ahead_;
  bool landing_clock_;  // the clock of the step the action lands at (kLandingSuffix)
};

constexpr std::size_t kCupVelocity[kActionDim] = {si::kCupVx, si::kCupVy, si::kCupW};
constexpr std::size_t kCupPose[kActionDim] = {si::kCupX, si::kCupY, si::kCupAngle};

const std::vector<std::unique_ptr<BuiltinFeatureMap>>& builtin_maps() {
  static const auto* maps = [] {
    auto* v = new std::vector<std::unique_ptr<BuiltinFeatureMap>>;
    v->push_back(std::make_unique<BuiltinFeatureMap>("state", "the 24 state numbers (the paper's input)", Blocks{}));
    v->push_back(std::make_unique<BuiltinFeatureMap>("state+clock", "the state and the step index t",
                                                     Blocks{true, false, false}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "state+clock+start", "the state, t, and the start's cup x and mean die x", Blocks{true, true, false}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "state+history", "the state and the previous state (the start repeated at t = 0)", Blocks{false, false, true}));
    v->push_back(std::make_unique<BuiltinFeatureMap>("state+clock+start_state", "the state, t and the whole start state",
                                                     Blocks{true, false, false, true}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "state+clock+start_state@dice",
        "the state, t and the whole start state, every x measured from the start's mean die x (that origin last)",
        Blocks{true, false, false, true, Current::state, true}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "state+clock+start_state+retry",
        "as state+clock+start_state, the clock and the start restarting when a failed attempt has come to rest "
        "(every die at rest, the lowest on the table, not stacked: attempt_start)",
        Blocks{true, false, false, true, Current::state, false, true}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "state+clock+start_state@dice+retry",
        "as state+clock+start_state@dice, the clock and the start restarting when a failed attempt has come to rest "
        "(every die at rest, the lowest on the table, not stacked: attempt_start)",
        Blocks{true, false, false, true, Current::state, true, true}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "clock+start_state", "open loop: t and the whole start state, not the current state (a pattern chosen at the start)",
        Blocks{true, false, false, true, Current::none}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "clock+start_state@dice",
        "open loop: t and the whole start state, every x measured from the start's mean die x (that origin last)",
        Blocks{true, false, false, true, Current::none, true}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "cup+clock+start_state",
        "a pattern with feedback on the cup alone: the cup's position and velocity, t and the whole start state",
        Blocks{true, false, false, true, Current::cup}));
    // Every map again, its regressor answering the cup velocity to set, then the pose; then
    // every one of those again, acting for the moment its action lands (delays), shown the
    // clock of the step it chooses at ("/ahead") or of the step it lands at ("/landing").
    const std::size_t base = v->size();
    enum class Twin { target, ahead, landing };
    auto twins = [v](std::size_t count, std::string_view suffix, const std::string& what, ActionTarget target, Twin twin) {
      for (std::size_t i = 0; i < count; ++i) {
        const BuiltinFeatureMap& m = *(*v)[i];
        v->push_back(std::make_unique<BuiltinFeatureMap>(m.name() + std::string(suffix), m.description() + "; " + what,
                                                         m.blocks(), twin == Twin::target ? target : m.target(),
                                                         twin != Twin::target, twin == Twin::landing));
      }
    };
    twins(base, kVelocityTargetSuffix, "answers the cup velocity to set (the action is its difference from the cup's velocity)",
          ActionTarget::velocity, Twin::target);
    twins(base, kPositionTargetSuffix, "answers the cup pose to servo to (the action sets the velocity 10/s times the pose error)",
          ActionTarget::position, Twin::target);
    const std::size_t targets = v->size();
    twins(targets, kAheadSuffix, "under delays, the cup moved ahead to where it is when the action lands", ActionTarget::impulse,
          Twin::ahead);
    twins(targets, kLandingSuffix,
          "under delays, the cup moved ahead to where it is when the action lands, and the clock of that step",
          ActionTarget::impulse, Twin::landing);
    return v;
  }();
  return *maps;
}

}  // namespace

State cup_ahead(const History& h) {
  State s = h.current();
  if (h.unseen.empty() && h.pending.empty()) return s;
  static const WorldConfig nominal{};
  const double dt = nominal.physics.control_dt, g = nominal.physics.gravity.y;
  const double n = nominal.physics.substeps, sub = dt / n;
  // Box2D's semi-implicit Euler over the substeps: v += g sub, then p += v sub, n times.
  auto run = [&](const Action& a) {
    s[si::kCupVx] += a[0];
    s[si::kCupVy] += a[1];
    s[si::kCupW] += a[2];
    s[si::kCupX] += s[si::kCupVx] * dt;
    s[si::kCupY] += s[si::kCupVy] * dt + g * sub * sub * n * (n + 1.0) / 2.0;
    s[si::kCupAngle] += s[si::kCupW] * dt;
    s[si::kCupVy] += g * dt;
  };
  for (const Action& a : h.unseen) run(a);
  for (const Action& a : h.pending) run(a);
  return s;
}

void check_ahead_world(const FeatureMap& map, const WorldConfig& world) {
  if (!map.ahead()) return;
  const PhysicsConfig nominal{}, &p = world.physics;
  if (p.gravity.x != nominal.gravity.x || p.gravity.y != nominal.gravity.y || p.control_dt != nominal.control_dt ||
      p.substeps != nominal.substeps)
    throw ConfigError("feature map \"" + map.name() +
                      "\" moves the cup ahead in the default world's physics (gravity, control_dt, substeps); this "
                      "world's differ: use the map without \"" +
                      std::string(map.name().ends_with(kLandingSuffix) ? kLandingSuffix : kAheadSuffix) + "\"");
}

void FeatureMap::label(const History& h, const Action& action, std::span<double> out) const {
  State scratch;
  const State& s = acting_state(*this, h, scratch);
  for (std::size_t k = 0; k < kActionDim; ++k) {
    switch (target()) {
      case ActionTarget::impulse: out[k] = action[k]; break;
      case ActionTarget::velocity: out[k] = action[k] + s[kCupVelocity[k]]; break;
      case ActionTarget::position:
        out[k] = s[kCupPose[k]] + (action[k] + s[kCupVelocity[k]]) / kPositionGain - (k == 0 ? origin_x(h) : 0.0);
        break;
    }
  }
}

Action FeatureMap::action(const History& h, std::span<const double> output) const {
  State scratch;
  const State& s = acting_state(*this, h, scratch);
  Action a;
  for (std::size_t k = 0; k < kActionDim; ++k) {
    switch (target()) {
      case ActionTarget::impulse: a[k] = output[k]; break;
      case ActionTarget::velocity: a[k] = output[k] - s[kCupVelocity[k]]; break;
      case ActionTarget::position:
        a[k] = kPositionGain * (output[k] + (k == 0 ? origin_x(h) : 0.0) - s[kCupPose[k]]) - s[kCupVelocity[k]];
        break;
    }
  }
  return a;
}

const FeatureMap& feature_map(std::string_view name) {
  for (const auto& m : builtin_maps())
    if (m->name() == name) return *m;
  std::string known;
  for (const auto& n : feature_map_names()) known += (known.empty() ? "" : ", ") + n;
  throw ConfigError("unknown feature map \"" + std::string(name) + "\"; known: " + known);
}

std::vector<std::string> feature_map_names() {
  std::vector<std::string> out;
  for (const auto& m : builtin_maps()) out.push_back(m->name());
  return out;
}

const FeatureMap& state_features() { return *builtin_maps().front(); }

}  // namespace dicestack
