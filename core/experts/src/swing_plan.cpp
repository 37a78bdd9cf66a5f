#include "swing_plan.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace dicestack::detail {
namespace {

namespace si = state_index;

// Quintic bases on u in [0, 1]: position from 0 to 1 with zero end velocities and
// accelerations, and a unit initial velocity that vanishes at both ends with zero accelerations.
double blend(double u) { return u * u * u * (10.0 + u * (-15.0 + 6.0 * u)); }
double blend_d(double u) { return 30.0 * u * u * (1.0 - u) * (1.0 - u); }
double launch(double u) { return u + u * u * u * (-6.0 + u * (8.0 - 3.0 * u)); }
double launch_d(double u) { return 1.0 + u * u * (-18.0 + u * (32.0 - 15.0 * u)); }
// Reaches a unit final velocity from rest at zero displacement at both ends.
double arrive(double u) { return u * u * u * (-4.0 + u * (7.0 - 3.0 * u)); }
double arrive_d(double u) { return u * u * (-12.0 + u * (28.0 - 15.0 * u)); }

}  // namespace

SwingPlan::SwingPlan(const SwingParams& params, const ExpertConfig& config, const WorldConfig& world,
                     const State& anchor, int anchor_step)
    : p_(params),
      gain_(config.gain),
      cup_(cup_geometry(world.cup)),
      table_(table_height(world.walls)),
      wall_left_(world.walls.left_x + world.walls.radius),
      wall_right_(world.walls.right_x - world.walls.radius),
      margin_(config.wall_margin),
      g_dt_(-world.physics.gravity.y * world.physics.control_dt),
      dt_(world.physics.control_dt),
      anchor_step_(anchor_step),
      anchor_(anchor) {
  double mean_x = 0.0;
  for (std::size_t i = 0; i < kDiceCount; ++i) mean_x += anchor[si::die(i)] / static_cast<double>(kDiceCount);
  xc_ = mean_x + p_.centre_offset;
  xstop_ = safe_x(xc_ + p_.stop_offset);
  v0_ = anchor[si::kCupVx];
  wx_ = {anchor[si::kCupX]};
  wt_ = {0.0};
  double t = 0.0;
  for (int i = 0; i < p_.half_swings; ++i) {
    const double side = (i % 2 == 0) ? p_.first_direction : -p_.first_direction;
    wx_.push_back(safe_x(xc_ + side * p_.amplitude));
    t += std::max(1.0, std::round(i == 0 ? 0.6 * p_.half_period : p_.half_period));
    wt_.push_back(t);
  }
  wx_.push_back(xstop_);
  wt_.push_back(t + std::max(1.0, std::round(p_.final_duration)));
  stop_speed_ = (xstop_ > wx_[wx_.size() - 2] ? 1.0 : -1.0) * p_.stop_speed;
}

double SwingPlan::aim(double x) const { return std::numbers::pi - std::atan((x - xc_) / p_.pivot_depth); }

double SwingPlan::lowest(double angle) const {
  double m = 1e9;
  for (const auto& seg : cup_.segments)
    for (const Vec2 q : {seg.a, seg.b}) m = std::min(m, to_world({0.0, 0.0}, angle, q).y - seg.radius);
  return -m;
}

double SwingPlan::reach(double angle, double side) const { return cup_reach(cup_, angle, side); }

double SwingPlan::safe_x(double x) const {
  // The reach depends on the tilt, which depends on x: a few fixed-point passes settle it.
  for (int pass = 0; pass < 3; ++pass) {
    const double a = aim(x);
    x = std::clamp(x, wall_left_ + margin_ + reach(a, -1.0), wall_right_ - margin_ - reach(a, 1.0));
  }
  return x;
}

bool SwingPlan::finished(int step) const {
  if (release_k_ < 0) return false;
  const double lift_steps = p_.lift_speed > 0.0 ? p_.lift_height / (p_.lift_speed * dt_) : 0.0;
  return step - anchor_step_ - release_k_ > std::max(1.0, p_.release_steps) + lift_steps;
}

void SwingPlan::reference_x(double k, double& x, double& v) const {
  std::size_t i = 1;
  while (i + 1 < wx_.size() && k >= wt_[i]) ++i;
  const double steps = wt_[i] - wt_[i - 1];
  const double u = std::clamp((k - wt_[i - 1]) / steps, 0.0, 1.0);
  const double seconds = steps * dt_;
  const double dx = wx_[i] - wx_[i - 1];
  x = wx_[i - 1] + dx * blend(u);
  v = dx * blend_d(u) / seconds;
  if (i == 1) {
    x += v0_ * seconds * launch(u);
    v += v0_ * launch_d(u);
  }
  if (i + 1 == wx_.size()) {
    x += stop_speed_ * seconds * arrive(u);
    v += stop_speed_ * arrive_d(u);
  }
}

Action SwingPlan::act(const State& s, int step) {
  const double k = static_cast<double>(step - anchor_step_);
  double x = xstop_, vx = 0.0, angle = 0.0, w = 0.0;
  if (stop_k_ < 0) {
    reference_x(k, x, vx);
    if (k >= wt_.back()) {
      stop_k_ = static_cast<int>(k);
      tilt_at_stop_ = aim(xstop_) - std::numbers::pi;
    }
  }
  double lift = 0.0, vy = 0.0;
  if (stop_k_ < 0) {
    const double r = (x - xc_) / p_.pivot_depth;
    angle = std::numbers::pi - std::atan(r);
    w = -(vx / p_.pivot_depth) / (1.0 + r * r);
  } else {
    x = xstop_;
    vx = 0.0;
    const double tau = std::max(0.5, p_.tilt_time);
    const double since = k - stop_k_;
    const double tilt = p_.end_tilt + (tilt_at_stop_ - p_.end_tilt) * std::exp(-since / tau);
    const double tilt_rate = -(tilt - p_.end_tilt) / (tau * dt_);
    angle = std::numbers::pi + tilt;
    w = tilt_rate;
    if (since >= p_.settle_steps) {
      if (release_k_ < 0) {
        release_k_ = static_cast<int>(k);
        release_x_ = 0.0;
        for (std::size_t i = 0; i < kDiceCount; ++i) release_x_ += s[si::die(i)] / static_cast<double>(kDiceCount);
        release_x_ = safe_x(release_x_);
        hover_y_ = table_ + p_.clearance + lowest(angle);
      }
      // Centre over the dice and turn upright, then rise straight up.
      const double span = std::max(1.0, p_.release_steps);
      const double u = std::clamp((k - release_k_) / span, 0.0, 1.0);
      x = xstop_ + (release_x_ - xstop_) * blend(u);
      vx = (release_x_ - xstop_) * blend_d(u) / (span * dt_);
      angle = std::numbers::pi + tilt * (1.0 - blend(u));
      w = tilt_rate * (1.0 - blend(u)) - tilt * blend_d(u) / (span * dt_);
      if (u >= 1.0) {
        const double rise = (k - release_k_ - span) * dt_ * p_.lift_speed;
        lift = std::min(rise, p_.lift_height);
        if (rise < p_.lift_height) vy = p_.lift_speed;
      }
    }
  }
  double y = table_ + p_.clearance + lowest(angle);
  if (release_k_ >= 0) y = std::max(y, hover_y_) + lift;
  double vx_cmd = vx + gain_ * (x - s[si::kCupX]);
  // Hard guard: never command a velocity that would carry the cup (at its actual tilt) to within
  // half the margin of a side wall in about two steps.
  const double hi = wall_right_ - 0.5 * margin_ - reach(s[si::kCupAngle], 1.0);
  const double lo = wall_left_ + 0.5 * margin_ + reach(s[si::kCupAngle], -1.0);
  const double rate = 0.5 / dt_;
  vx_cmd = std::clamp(vx_cmd, (lo - s[si::kCupX]) * rate, (hi - s[si::kCupX]) * rate);
  const double turn = std::remainder(angle - s[si::kCupAngle], 2.0 * std::numbers::pi);
  return {vx_cmd - s[si::kCupVx], vy + gain_ * (y - s[si::kCupY]) - s[si::kCupVy] + g_dt_, w + gain_ * turn - s[si::kCupW]};
}

}  // namespace dicestack::detail
