#include <dicestack/datasets/features.hpp>

#include <algorithm>
#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/geometry.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {
namespace {

namespace si = state_index;

using Current = FeatureSpec::Current;
using Start = FeatureSpec::Start;
using Timing = FeatureSpec::Timing;
constexpr std::size_t kCupParts[] = {si::kCupX, si::kCupY, si::kCupAngle, si::kCupVx, si::kCupVy, si::kCupW};
constexpr std::size_t kLinkColumns = 6;  // the "links" part: three angles, three rates

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

// The law an "/osc" map carries: operational-space control in the default world, over one
// control step.
const WorldConfig& osc_world() {
  static const WorldConfig nominal{};
  return nominal;
}

// The arm and cup as `h` shows them now, for the law. Throws InputError without the links.
ArmMotion shown_motion(const FeatureMap& m, const History& h) {
  if (h.links.size() != h.states.size())
    throw InputError("feature map \"" + m.name() + "\" servos the cup through the arm's links, and this episode has no readings of them");
  const ArmLinks& l = h.links.back();
  const State& s = h.current();
  static const CupGeometry cup = cup_geometry(osc_world().cup);
  ArmMotion now;
  now.angles = {l.angles[0], l.angles[1], l.angles[2], s[si::kCupAngle]};
  now.rates = {l.rates[0], l.rates[1], l.rates[2], s[si::kCupW]};
  now.cup_velocity = {s[si::kCupVx], s[si::kCupVy]};
  now.cup_mass = cup.mass;
  now.cup_inertia = cup.inertia;
  return now;
}

// One line for listings, from the spec's parts.
std::string describe(const FeatureSpec& f) {
  std::string out = f.current == Current::state ? "the 24 state numbers"
                    : f.current == Current::cup ? "the cup's six numbers"
                                                : "no current state (open loop)";
  if (f.links) out += ", the arm's link angles and rates";
  if (f.clock) out += ", the step index t";
  if (f.start == Start::summary) out += ", the start's cup x and mean die x";
  if (f.start == Start::whole) out += ", the whole start state";
  if (f.previous) out += ", the previous state";
  if (f.dice_frame) out += "; every x measured from the start's mean die x (that origin last)";
  if (f.restart) out += "; the clock and the start restart where a failed attempt has come to rest";
  if (f.target == ActionTarget::velocity) out += "; answers the cup velocity to set";
  if (f.target == ActionTarget::position) out += "; answers the cup pose to servo to (10/s times the pose error)";
  if (f.target == ActionTarget::torque) out += "; answers the arm's four joint torques";
  if (f.target == ActionTarget::osc)
    out += "; answers the cup pose to servo to and the posture's acceleration, which operational-space control turns into "
           "the arm's joint torques, held through the step";
  if (f.timing != Timing::now) out += "; under delays, the cup moved ahead to where it is when the action lands";
  if (f.timing == Timing::landing) out += ", and the clock of that step";
  return out;
}

class SpecFeatureMap final : public FeatureMap {
 public:
  explicit SpecFeatureMap(const FeatureSpec& spec) : spec_(spec), name_(to_string(spec)), description_(describe(spec)) {}

  std::string name() const override { return name_; }
  // An "/osc" map's answers are the pose and the posture (version 2); a model of the pose alone
  // (version 1) would be read short, and is refused.
  int version() const override { return spec_.target == ActionTarget::osc ? 2 : 1; }
  std::string description() const override { return description_; }
  ActionTarget target() const override { return spec_.target; }
  bool ahead() const override { return spec_.timing != Timing::now; }
  bool attempts() const override { return spec_.restart; }
  bool reads_links() const override { return spec_.links; }
  double origin_x(const History& h) const override { return spec_.dice_frame ? mean_dice_x(start_of(h)) : 0.0; }

  std::size_t width() const override {
    return current_width() + (spec_.links ? kLinkColumns : 0) + (spec_.clock ? 1 : 0) + (spec_.start == Start::summary ? 2 : 0) +
           (spec_.start == Start::whole ? kStateDim : 0) + (spec_.previous ? kStateDim : 0) + (spec_.dice_frame ? 1 : 0);
  }

  std::vector<std::string> column_names() const override {
    std::vector<std::string> out;
    if (spec_.current == Current::state)
      for (auto n : state_names()) out.emplace_back(n);
    if (spec_.current == Current::cup)
      for (auto k : kCupParts) out.emplace_back(state_names()[k]);
    if (spec_.links)
      for (const char* what : {"angle", "rate"})
        for (int i = 0; i < 3; ++i) out.push_back("link" + std::to_string(i) + "_" + what);
    if (spec_.clock) out.emplace_back("t");
    if (spec_.start == Start::summary) out.insert(out.end(), {"start_cup_x", "start_dice_mean_x"});
    if (spec_.start == Start::whole)
      for (auto n : state_names()) out.push_back("start_" + std::string(n));
    if (spec_.previous)
      for (auto n : state_names()) out.push_back("prev_" + std::string(n));
    if (spec_.dice_frame) out.emplace_back("origin_x");
    return out;
  }

  void compute(const History& h, std::span<double> out) const override {
    State scratch;
    const State& s = acting_state(*this, h, scratch);
    const std::size_t begin = spec_.restart ? attempt_begin(h) : 0;
    const State& start = h.states[begin];
    // Under the dice frame every x is measured from the start's mean die x (that origin last).
    const double x0 = spec_.dice_frame ? mean_dice_x(start) : 0.0;
    const auto put_state = [&](const State& from, std::size_t at) {
      std::copy(from.begin(), from.end(), out.begin() + static_cast<std::ptrdiff_t>(at));
      if (!spec_.dice_frame) return;
      out[at + si::kCupX] -= x0;
      for (std::size_t i = 0; i < kDiceCount; ++i) out[at + si::die(i)] -= x0;
    };
    std::size_t at = 0;
    if (spec_.current == Current::state) put_state(s, 0);
    if (spec_.current == Current::cup)
      for (auto k : kCupParts) out[at++] = s[k] - (k == si::kCupX ? x0 : 0.0);
    at = current_width();
    if (spec_.links) {
      if (h.links.size() != h.states.size())
        throw InputError("feature map \"" + name_ + "\" reads the arm's links, and this episode has no readings of them");
      const ArmLinks& l = h.links.back();
      std::copy(l.angles.begin(), l.angles.end(), out.begin() + static_cast<std::ptrdiff_t>(at));
      std::copy(l.rates.begin(), l.rates.end(), out.begin() + static_cast<std::ptrdiff_t>(at + 3));
      at += kLinkColumns;
    }
    if (spec_.clock) out[at++] = static_cast<double>(h.t() - begin + (spec_.timing == Timing::landing ? h.pending.size() : 0));
    if (spec_.start == Start::summary) {
      out[at++] = start[si::kCupX] - x0;
      out[at++] = mean_dice_x(start) - x0;
    }
    if (spec_.start == Start::whole) {
      put_state(start, at);
      at += kStateDim;
    }
    if (spec_.previous) {
      put_state(h.states.size() >= 2 ? h.states[h.states.size() - 2] : s, at);
      at += kStateDim;
    }
    if (spec_.dice_frame) out[at] = x0;
  }

 private:
  const State& start_of(const History& h) const { return spec_.restart ? h.states[attempt_begin(h)] : h.start(); }

  std::size_t current_width() const {
    return spec_.current == Current::state ? kStateDim : spec_.current == Current::cup ? std::size(kCupParts) : 0;
  }

  FeatureSpec spec_;
  std::string name_, description_;
};

constexpr std::size_t kCupVelocity[kActionDim] = {si::kCupVx, si::kCupVy, si::kCupW};
constexpr std::size_t kCupPose[kActionDim] = {si::kCupX, si::kCupY, si::kCupAngle};

// The input sets `dicestack learners` lists, each with every target and timing.
constexpr std::string_view kListedInputs[] = {"state",
                                              "state+clock",
                                              "state+clock+start",
                                              "state+history",
                                              "state+clock+start_state",
                                              "state+clock+start_state@dice",
                                              "state+clock+start_state+retry",
                                              "state+clock+start_state@dice+retry",
                                              "clock+start_state",
                                              "clock+start_state@dice",
                                              "cup+clock+start_state"};

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

void check_map_world(const FeatureMap& map, const WorldConfig& world) {
  if ((map.reads_links() || map.action_kind() == ActionKind::joint_torque) && world.embodiment != Embodiment::arm)
    throw ConfigError("feature map \"" + map.name() + "\" " +
                      (map.reads_links() ? "reads the arm's links" : "answers the arm's joint torques") +
                      "; this world's cup floats: run it with the arm (--embodiment arm)");
  if (map.target() == ActionTarget::osc && (!(world.arm == osc_world().arm) || world.physics.control_dt != osc_world().physics.control_dt))
    throw ConfigError("feature map \"" + map.name() + "\" carries the operational-space law of the default world's arm and "
                      "control step; this world's differ: train the policy in this world with a \"/torque\" map");
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
  if (action.kind() != action_kind())
    throw InputError("feature map \"" + name() + "\" answers " + std::string(action_kind_name(action_kind())) +
                     " actions; a label is for the " + std::string(action_kind_name(action.kind())) + " controller");
  if (target() == ActionTarget::torque) {
    std::copy(action.begin(), action.end(), out.begin());
    return;
  }
  if (target() == ActionTarget::osc) {
    // The pose whose servo velocity the law turns into these torques, and the posture's
    // acceleration they ask beyond the law's own: the law's inverse. The teacher's torques in the
    // task's null space move the links through the held step, and with them the cup and the
    // walls the links reach (docs/arm.md, "The map's own limit").
    const WorldConfig& w = osc_world();
    const LawRequest asked = arm_torques_inverse(w.arm, shown_motion(*this, h), {action[0], action[1], action[2], action[3]},
                                                 w.physics.control_dt, w.physics.gravity);
    const std::array<double, kActionDim> velocity{asked.cup.velocity.x, asked.cup.velocity.y, asked.cup.angular_velocity};
    for (std::size_t k = 0; k < kActionDim; ++k)
      out[k] = h.current()[kCupPose[k]] + velocity[k] / kPositionGain - (k == 0 ? origin_x(h) : 0.0);
    out[kActionDim] = asked.posture;
    return;
  }
  State scratch;
  const State& s = acting_state(*this, h, scratch);
  for (std::size_t k = 0; k < kActionDim; ++k) {
    switch (target()) {
      case ActionTarget::impulse:
      case ActionTarget::torque:
      case ActionTarget::osc: out[k] = action[k]; break;
      case ActionTarget::velocity: out[k] = action[k] + s[kCupVelocity[k]]; break;
      case ActionTarget::position:
        out[k] = s[kCupPose[k]] + (action[k] + s[kCupVelocity[k]]) / kPositionGain - (k == 0 ? origin_x(h) : 0.0);
        break;
    }
  }
}

Action FeatureMap::action(const History& h, std::span<const double> output) const {
  if (target() == ActionTarget::torque) return Action::torques({output[0], output[1], output[2], output[3]});
  if (target() == ActionTarget::osc) {
    std::array<double, kActionDim> velocity{};
    for (std::size_t k = 0; k < kActionDim; ++k)
      velocity[k] = kPositionGain * (output[k] + (k == 0 ? origin_x(h) : 0.0) - h.current()[kCupPose[k]]);
    const WorldConfig& w = osc_world();
    return Action::torques(arm_torques(w.arm, shown_motion(*this, h), {velocity[0], velocity[1]}, velocity[2],
                                       w.physics.control_dt, w.physics.gravity, output[kActionDim]));
  }
  State scratch;
  const State& s = acting_state(*this, h, scratch);
  Action a;
  for (std::size_t k = 0; k < kActionDim; ++k) {
    switch (target()) {
      case ActionTarget::impulse:
      case ActionTarget::torque:
      case ActionTarget::osc: a[k] = output[k]; break;
      case ActionTarget::velocity: a[k] = output[k] - s[kCupVelocity[k]]; break;
      case ActionTarget::position:
        a[k] = kPositionGain * (output[k] + (k == 0 ? origin_x(h) : 0.0) - s[kCupPose[k]]) - s[kCupVelocity[k]];
        break;
    }
  }
  return a;
}

std::span<const std::string_view> FeatureMap::answer_names() const {
  static constexpr std::array<std::string_view, kActionDim + 1> osc{"dvx", "dvy", "dw", "posture"};
  if (target() == ActionTarget::osc) return osc;
  return action_names(target() == ActionTarget::torque ? ActionKind::joint_torque : ActionKind::cup);
}

const FeatureMap& feature_map(std::string_view name) {
  const FeatureSpec spec = parse_feature_spec(name);
  // Maps are built on first use and kept: a model holds a reference to its map for good.
  static std::mutex mutex;
  static auto* maps = new std::map<std::string, std::unique_ptr<const SpecFeatureMap>, std::less<>>;
  const std::scoped_lock lock(mutex);
  auto& slot = (*maps)[to_string(spec)];
  if (!slot) slot = std::make_unique<const SpecFeatureMap>(spec);
  return *slot;
}

std::vector<std::string> feature_map_names() {
  std::vector<std::string> out;
  for (const std::string_view timing : {std::string_view{}, kAheadSuffix, kLandingSuffix})
    for (const std::string_view target : {std::string_view{}, kVelocityTargetSuffix, kPositionTargetSuffix})
      for (const std::string_view inputs : kListedInputs)
        out.push_back(std::string(inputs) + std::string(target) + std::string(timing));
  return out;
}

const FeatureMap& state_features() {
  static const FeatureMap& state = feature_map("state");
  return state;
}

}  // namespace dicestack
