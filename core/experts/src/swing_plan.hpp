#pragma once
// Private to core/: the swing reference trajectory and its tracking controller, shared by the
// experts in expert.cpp.
#include <vector>

#include <dicestack/core/expert.hpp>
#include <dicestack/core/geometry.hpp>

namespace dicestack::detail {

/// A swing plan anchored at one state and step: waypoints in x joined by quintic segments (the
/// first starts at the cup's velocity, the rest at rest), the cup's angle aimed at a pivot below
/// the swing centre, its height keeping `clearance` over the table. After the stop the cup holds
/// x and turns to end_tilt. act() is a deterministic function of the state, the step and the
/// plan's own stop flag, so a copy simulated ahead reproduces the run exactly.
class SwingPlan {
 public:
  SwingPlan() = default;
  SwingPlan(const SwingParams& params, const ExpertConfig& config, const WorldConfig& world, const State& anchor,
            int anchor_step);

  /// The action at env step `step` (>= the anchor step) in state `s`.
  Action act(const State& s, int step);

  bool valid() const { return !wx_.empty(); }
  /// True once the plan has stopped, released and lifted the cup: nothing it does changes the dice any more.
  bool finished(int step) const;
  int anchor_step() const { return anchor_step_; }
  const State& anchor() const { return anchor_; }
  const SwingParams& params() const { return p_; }

 private:
  void reference_x(double k, double& x, double& v) const;
  double aim(double x) const;
  double lowest(double angle) const;
  double reach(double angle, double side) const;
  double safe_x(double x) const;

  SwingParams p_;
  double gain_ = 10.0;
  CupGeometry cup_;
  double table_ = 1.0, wall_left_ = 0.0, wall_right_ = 0.0, margin_ = 0.1;
  double g_dt_ = 0.0, dt_ = 1.0 / 30.0;
  int anchor_step_ = 0;
  State anchor_{};
  double xc_ = 0.0, xstop_ = 0.0, v0_ = 0.0, stop_speed_ = 0.0;
  std::vector<double> wx_, wt_;
  int stop_k_ = -1;
  double tilt_at_stop_ = 0.0;
  int release_k_ = -1;
  double release_x_ = 0.0;
  double hover_y_ = 0.0;
};

}  // namespace dicestack::detail
