#include <dicestack/core/types.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include <dicestack/core/error.hpp>

namespace dicestack {

const std::array<std::string_view, kStateDim>& state_names() {
  static constexpr std::array<std::string_view, kStateDim> names{
      "cup_x",   "cup_y",   "cup_angle", "die0_x",  "die0_y",  "die0_angle", "die0_vx", "die0_vy",
      "die0_w",  "die1_x",  "die1_y",    "die1_angle", "die1_vx", "die1_vy", "die1_w", "die2_x",
      "die2_y",  "die2_angle", "die2_vx", "die2_vy", "die2_w",  "cup_vx",  "cup_vy",  "cup_w"};
  return names;
}

double mean_dice_x(const State& s) {
  double x = 0.0;
  for (std::size_t i = 0; i < kDiceCount; ++i) x += s[state_index::die(i)];
  return x / static_cast<double>(kDiceCount);
}

const std::array<std::string_view, kActionDim>& action_names() {
  static constexpr std::array<std::string_view, kActionDim> names{"dvx", "dvy", "dw"};
  return names;
}

const std::array<std::string_view, kJointCount>& torque_names() {
  static constexpr std::array<std::string_view, kJointCount> names{"tau0", "tau1", "tau2", "tau3"};
  return names;
}

std::span<const std::string_view> action_names(ActionKind kind) {
  if (kind == ActionKind::cup) return action_names();
  return torque_names();
}

std::string_view action_kind_name(ActionKind kind) { return kind == ActionKind::cup ? "cup" : "joint_torque"; }

namespace {

template <std::size_t N>
std::array<double, N> to_array(std::span<const double> values, std::string_view what, const char* kind) {
  if (values.size() != N)
    throw InputError(std::string(what) + ": " + kind + " needs " + std::to_string(N) + " values, got " +
                     std::to_string(values.size()));
  require_finite(values, what);
  std::array<double, N> out{};
  std::copy(values.begin(), values.end(), out.begin());
  return out;
}

}  // namespace

State to_state(std::span<const double> values, std::string_view what) {
  return to_array<kStateDim>(values, what, "a state");
}

Action to_action(std::span<const double> values, std::string_view what, ActionKind kind) {
  if (kind == ActionKind::joint_torque) return Action::torques(to_array<kJointCount>(values, what, "a joint-torque action"));
  const auto a = to_array<kActionDim>(values, what, "an action");
  return Action{a[0], a[1], a[2]};
}

void require_finite(std::span<const double> values, std::string_view what) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!std::isfinite(values[i]))
      throw InputError(std::string(what) + ": element " + std::to_string(i) + " is " +
                       (std::isnan(values[i]) ? "NaN" : "infinite") + "; values must be finite");
}

}  // namespace dicestack
