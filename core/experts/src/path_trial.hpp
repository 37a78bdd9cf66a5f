#pragma once
// One simulated episode of a path follower, scored: shared by the tracker's per-start search
// and by the refinement of a path over many starts (path_refine.hpp).
#include <cstdint>

#include <dicestack/core/env.hpp>
#include <dicestack/core/tracker.hpp>

namespace dicestack::tracker_detail {

/// One simulated episode: higher is better; only a realistic success scores above 0 (an earlier
/// success higher); a failure scores minus its stack shortfall, minus 1000 with a wall touched.
struct Trial {
  double score = -1e300;
  bool success = false;
};

/// `follower` played from `start` in `sim` for its length plus `hold_steps`, each action told in
/// joint torques under the joint_torque `controller`. A `noise` component above 0 adds
/// executed-action noise of that std (x action.scale) on that axis, drawn from `noise_seed`.
Trial simulate(const PathFollower& follower, DiceEnv& sim, const EnvSnapshot& start, int hold_steps, ActionKind controller,
               const Action& noise = {}, std::uint64_t noise_seed = 0);

/// `path` with each step's action folded into the velocity during the step (the state's plus the
/// action's), the actions then zero: the form a path takes once its pose or velocity is changed.
CupPath folded(const CupPath& path);

}  // namespace dicestack::tracker_detail
