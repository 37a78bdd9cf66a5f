#pragma once
// The planar arm that holds the cup in a world whose embodiment is arm: its rest posture for a
// cup pose (what a world rebuilt at a state, and a drawing, use) and the operational-space
// controller that turns a wanted cup velocity into joint torques within the arm's limits.
// docs/arm.md.
#include <array>

#include <dicestack/core/vec2.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// Where the arm's links lie.
struct ArmPosture {
  std::array<double, 3> link_angles{};  ///< each link's absolute direction, shoulder link first, rad
  std::array<Vec2, 4> joints{};         ///< shoulder, elbow, second elbow, wrist (the cup's centre), m
  bool reached = true;                  ///< false: the wrist is out of reach; the arm is stretched towards it
};

/// The rest posture holding the wrist at `wrist`: the last link's near end at three quarters of
/// the first two links' reach from the shoulder (as near to that as the last link allows), so
/// the elbow is neither folded nor stretched; the elbow always bent the same way (clockwise from
/// the shoulder's line to that end). The same for the same point, so a world rebuilt at a state
/// holds the same arm.
ArmPosture arm_posture(const ArmConfig& arm, Vec2 wrist);

/// The four joints' angles from the links' absolute ones and the cup's (the shoulder's absolute,
/// each other one its body's less the body's before it). The same of the rates gives the joints'
/// rates.
inline std::array<double, 4> arm_joint_angles_of(const std::array<double, 3>& links, double cup) {
  return {links[0], links[1] - links[0], links[2] - links[1], cup - links[2]};
}

/// The posture of `link_angles` (joints by forward kinematics from the shoulder).
ArmPosture arm_posture_of(const ArmConfig& arm, const std::array<double, 3>& link_angles);
/// The wrist's (the cup's centre's) velocity, m/s, when the links at `link_angles` turn at
/// `link_rates` (absolute, rad/s).
Vec2 arm_wrist_velocity(const ArmConfig& arm, const std::array<double, 3>& link_angles, const std::array<double, 3>& link_rates);

/// The links' absolute rates (rad/s) that move the wrist at `velocity` (m/s): the least-norm
/// rates (damped near a stretched arm), plus a motion the wrist does not feel that returns the
/// last link to its rest posture's direction at arm.posture_gain.
std::array<double, 3> arm_link_rates(const ArmConfig& arm, const std::array<double, 3>& link_angles, Vec2 velocity);

/// The arm and the cup it holds as one chain: each body's absolute angle and rate (the three
/// links, then the cup), the cup's velocity, and its mass and inertia about its centre.
struct ArmMotion {
  std::array<double, 4> angles{};
  std::array<double, 4> rates{};
  Vec2 cup_velocity;
  double cup_mass = 0.0;
  double cup_inertia = 0.0;
};

/// Operational-space control: the four joint torques (N m; shoulder, elbows, wrist; each acting
/// on its body and back on the one before) that bring the cup's velocity to `velocity` and its
/// turn to `angular_velocity` within `dt`, from the chain's own dynamics (mass matrix,
/// centripetal terms, gravity), with the spare degree of freedom pulled to the rest posture in
/// the task's null space, `posture` (rad/s^2) added to that pull along the null space's unit
/// axis (arm_posture_axis); no joint asked past its arm.speed_limit. Where the torques would pass
/// their arm.torque_limit, the task's share of them (the cup's wanted acceleration, with the
/// correction of the chain's centripetal drift, and `posture`) is scaled down as a whole, keeping
/// what holds the arm up and pulls it to its rest posture: clipping each joint alone sent the cup
/// elsewhere than asked and turned the arm. When holding and that pull alone pass a limit, no
/// task share is given and they are clipped. Each torque is then clipped to its limit. Loads the
/// model does not know (dice in the cup) are left to the next call's velocity error.
std::array<double, 4> arm_torques(const ArmConfig& arm, const ArmMotion& now, Vec2 velocity, double angular_velocity,
                                  double dt, Vec2 gravity, double posture = 0.0);

/// The angular accelerations of the chain's bodies that leave the cup's centre and angle where
/// they are (the task's null space: the elbows fold, the cup stays), as a unit vector:
/// (l1 l2 sin(a2 - a1), l0 l2 sin(a0 - a2), l0 l1 sin(a1 - a0), 0) over its norm, for the links'
/// lengths l and absolute angles a; zero where the arm is stretched straight.
std::array<double, 4> arm_posture_axis(const ArmConfig& arm, const std::array<double, 4>& angles);

/// A cup velocity (m/s) and turn (rad/s).
struct CupVelocity {
  Vec2 velocity;
  double angular_velocity = 0.0;
};

/// What arm_torques is asked: the cup's velocity and turn, and the posture's acceleration.
struct LawRequest {
  CupVelocity cup;
  double posture = 0.0;
};

/// arm_torques' inverse: what it must be asked (same `now`, `dt` and `gravity`) to give
/// `torques`. Four torques, four numbers: exact wherever no limit binds (the speed's, the
/// torques'), for any torques, also a teacher's that move the spare degree of freedom their own
/// way. A policy that answers the cup's motion and acts in held joint torques is labelled so from
/// a teacher's torques.
LawRequest arm_torques_inverse(const ArmConfig& arm, const ArmMotion& now, const std::array<double, 4>& torques, double dt,
                               Vec2 gravity);

/// Joint-space control: the four joint torques that give the chain's absolute angles (the three
/// links, then the cup) the accelerations `accel` (rad/s^2), from the chain's own dynamics as
/// arm_torques uses them; each torque clipped to its limit.
std::array<double, 4> arm_joint_space_torques(const ArmConfig& arm, const ArmMotion& now, const std::array<double, 4>& accel,
                                              Vec2 gravity);

/// The least change of four joint torques held through a step of `dt` that changes the cup's
/// velocity at its end by `velocity_change` and its turn by `turn_change`, from the chain's
/// dynamics at `now` (linearised: what the contacts do is not in it; no limits applied).
std::array<double, 4> arm_torque_change(const ArmConfig& arm, const ArmMotion& now, Vec2 velocity_change, double turn_change,
                                        double dt);

}  // namespace dicestack
