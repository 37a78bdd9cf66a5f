#pragma once
// The state and action vectors every part of dicestack exchanges, in SI units.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace dicestack {

inline constexpr std::size_t kStateDim = 24;   ///< observed numbers per state (paper V-A)
inline constexpr std::size_t kActionDim = 3;   ///< (dvx, dvy, dw) per control step
inline constexpr std::size_t kJointCount = 4;  ///< the arm's joints: shoulder, elbow, second elbow, wrist
inline constexpr std::size_t kDiceCount = 3;

/// 24 numbers in the original recordings' order: cup x, y, angle; for die 0, 1, 2: x, y, angle,
/// vx, vy, angular velocity; then cup vx, vy, angular velocity. Metres, radians, seconds.
/// The cup position is its centre of mass.
using State = std::array<double, kStateDim>;

/// The arm's three links as its joint encoders give them: each link's absolute direction (rad)
/// and rate (rad/s), shoulder link first. With the cup's pose and velocity (in the State) they
/// fix the whole arm, whose spare degree of freedom the State alone does not show.
struct ArmLinks {
  std::array<double, 3> angles{};
  std::array<double, 3> rates{};
  friend constexpr bool operator==(const ArmLinks&, const ArmLinks&) = default;
};

/// What an action commands: the cup's velocity change (the paper's "force control", every
/// embodiment: the arm's operational-space controller realises it), or the arm's four joint
/// torques (the joint_torque controller).
/// Eight bytes, so an Action has no padding: ranks exchange Actions as plain bytes.
enum class ActionKind : std::uint64_t { cup, joint_torque };

/// One control step's command. A cup action is a velocity change of the cup applied at the
/// start of the step, (dvx, dvy, dw) in (m/s, m/s, rad/s); a joint-torque action is the four
/// torques (N m) the arm's joints hold through the step. Indexes and iterates like an array of
/// its size(); `Action{dvx, dvy, dw}` is a cup action.
class Action {
 public:
  constexpr Action() = default;  ///< the cup left alone: three zeros
  constexpr Action(double dvx, double dvy, double dw) : v_{dvx, dvy, dw, 0.0} {}
  /// Joint torques, shoulder first.
  static constexpr Action torques(const std::array<double, kJointCount>& t) {
    Action a;
    a.v_ = t;
    a.kind_ = ActionKind::joint_torque;
    return a;
  }
  /// Zeros of `kind`.
  static constexpr Action zeros(ActionKind kind) { return kind == ActionKind::cup ? Action{} : torques({}); }

  constexpr ActionKind kind() const { return kind_; }
  constexpr std::size_t size() const { return kind_ == ActionKind::cup ? kActionDim : kJointCount; }
  constexpr double& operator[](std::size_t i) { return v_[i]; }
  constexpr const double& operator[](std::size_t i) const { return v_[i]; }
  double* data() { return v_.data(); }
  const double* data() const { return v_.data(); }
  double* begin() { return v_.data(); }
  double* end() { return v_.data() + size(); }
  const double* begin() const { return v_.data(); }
  const double* end() const { return v_.data() + size(); }
  /// Same kind and the same values.
  friend constexpr bool operator==(const Action& a, const Action& b) { return a.kind_ == b.kind_ && a.v_ == b.v_; }

 private:
  std::array<double, kJointCount> v_{};  ///< unused trailing entries stay 0, so == compares them harmlessly
  ActionKind kind_ = ActionKind::cup;
};

/// The number of values an action of `kind` has: 3 (cup) or 4 (joint torques).
constexpr std::size_t action_dim(ActionKind kind) { return Action::zeros(kind).size(); }

/// Indices into a State.
namespace state_index {
inline constexpr std::size_t kCupX = 0, kCupY = 1, kCupAngle = 2;
inline constexpr std::size_t kCupVx = 21, kCupVy = 22, kCupW = 23;
/// First index of die i's block (x, y, angle, vx, vy, w).
constexpr std::size_t die(std::size_t i) { return 3 + 6 * i; }
}  // namespace state_index

/// The dice' mean x in `s`: where the tracker anchors a recording and the "@dice" feature maps
/// measure x from.
double mean_dice_x(const State& s);

/// Column names of a State: cup_x, cup_y, cup_angle, die0_x, ..., die2_w, cup_vx, cup_vy, cup_w.
const std::array<std::string_view, kStateDim>& state_names();

/// Column names of a cup Action: dvx, dvy, dw.
const std::array<std::string_view, kActionDim>& action_names();
/// Column names of a joint-torque Action: tau0 (the shoulder) to tau3 (the wrist).
const std::array<std::string_view, kJointCount>& torque_names();
/// The column names of an action of `kind`.
std::span<const std::string_view> action_names(ActionKind kind);
/// "cup" or "joint_torque": the controller an action of `kind` is for.
std::string_view action_kind_name(ActionKind kind);

/// A State from `values`; throws InputError naming `what` if there are not 24 finite values.
State to_state(std::span<const double> values, std::string_view what);

/// An Action of `kind` from `values`; throws InputError naming `what` if there are not
/// action_dim(kind) finite values.
Action to_action(std::span<const double> values, std::string_view what, ActionKind kind = ActionKind::cup);

/// Throws InputError naming `what` and the first index that is NaN or infinite.
void require_finite(std::span<const double> values, std::string_view what);

}  // namespace dicestack
