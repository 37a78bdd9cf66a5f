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
inline constexpr std::size_t kDiceCount = 3;

/// 24 numbers in the original recordings' order: cup x, y, angle; for die 0, 1, 2: x, y, angle,
/// vx, vy, angular velocity; then cup vx, vy, angular velocity. Metres, radians, seconds.
/// The cup position is its centre of mass.
using State = std::array<double, kStateDim>;

/// A velocity change of the cup applied at the start of a control step (the paper's "force
/// control"): (m/s, m/s, rad/s).
using Action = std::array<double, kActionDim>;

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

/// Column names of an Action: dvx, dvy, dw.
const std::array<std::string_view, kActionDim>& action_names();

/// A State from `values`; throws InputError naming `what` if there are not 24 finite values.
State to_state(std::span<const double> values, std::string_view what);

/// An Action from `values`; throws InputError naming `what` if there are not 3 finite values.
Action to_action(std::span<const double> values, std::string_view what);

/// Throws InputError naming `what` and the first index that is NaN or infinite.
void require_finite(std::span<const double> values, std::string_view what);

}  // namespace dicestack
