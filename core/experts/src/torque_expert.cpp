// A cup-space expert told in joint torques (expert.hpp, in_joint_torques).
#include <optional>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>

namespace dicestack {
namespace {

class JointTorqueExpert final : public Expert {
 public:
  explicit JointTorqueExpert(std::unique_ptr<Expert> cup) : cup_(std::move(cup)) {}
  std::string name() const override { return cup_->name(); }
  ActionKind controller() const override { return ActionKind::joint_torque; }

 private:
  void do_reset(std::uint64_t seed) override { cup_->reset(seed); }

  Action do_act(const DiceEnv& env, const State& sensed) override {
    if (env.config().embodiment != Embodiment::arm)
      throw InputError("expert " + name() + ": joint torques need a world whose embodiment is \"arm\"");
    const Action cup = cup_->act(env, {}, &sensed);
    if (!scratch_ || !(scratch_->config() == env.config())) scratch_.emplace(env.config());
    scratch_->restore(env.snapshot());
    return told_in_torques(*scratch_, cup);
  }

  std::unique_ptr<Expert> cup_;
  std::optional<DiceEnv> scratch_;  // where each cup action is told in torques
};

}  // namespace

Action told_in_torques(DiceEnv& env, const Action& cup) {
  if (env.config().embodiment != Embodiment::arm)
    throw InputError("a cup action told in joint torques needs a world whose embodiment is \"arm\"");
  const EnvSnapshot start = env.snapshot();
  const ArmMotion now = env.world().arm_motion();
  const State wanted = env.step(cup).observation;
  std::array<double, 4> torques = env.world().arm_step_torques();
  // Held torques lack the cup controller's feedback within the step: corrected once towards the
  // cup velocity the cup action ended the step at. One halves the velocity error in contact;
  // more gained nothing (docs/notebook/2026-11-28-arm-open-loop.md).
  env.restore(start);
  const State got = env.step(Action::torques(torques)).observation;
  env.restore(start);
  namespace si = state_index;
  const auto change = arm_torque_change(env.config().arm, now, {wanted[si::kCupVx] - got[si::kCupVx], wanted[si::kCupVy] - got[si::kCupVy]},
                                        wanted[si::kCupW] - got[si::kCupW], env.config().physics.control_dt);
  for (std::size_t j = 0; j < 4; ++j) torques[j] += change[j];
  return Action::torques(torques);
}

std::unique_ptr<Expert> in_joint_torques(std::unique_ptr<Expert> cup_expert) {
  return std::make_unique<JointTorqueExpert>(std::move(cup_expert));
}

Action cup_action_between(const State& before, const State& after, const WorldConfig& world) {
  namespace si = state_index;
  const double dt = world.physics.control_dt;
  return {after[si::kCupVx] - before[si::kCupVx] - world.physics.gravity.x * dt,
          after[si::kCupVy] - before[si::kCupVy] - world.physics.gravity.y * dt, after[si::kCupW] - before[si::kCupW]};
}

}  // namespace dicestack
