#include <dicestack/datasets/episode.hpp>

#include <cmath>

#include <dicestack/core/error.hpp>

namespace dicestack {

std::string_view to_string(StepSource source) {
  switch (source) {
    case StepSource::human: return "human";
    case StepSource::expert: return "expert";
    case StepSource::policy: return "policy";
    case StepSource::correction: return "correction";
  }
  return "unknown";
}

StepSource step_source_from(std::string_view text) {
  for (auto s : {StepSource::human, StepSource::expert, StepSource::policy, StepSource::correction})
    if (to_string(s) == text) return s;
  throw InputError("\"" + std::string(text.substr(0, 40)) + (text.size() > 40 ? "..." : "") + "\" is not one of human, expert, policy, correction");
}

void Episode::clear_transitions() {
  final_state.reset();
  final_links.reset();
  rewards.clear();
  terminated = truncated = false;
}

namespace {

// The arm's readings beyond the links of each state: the joints' torques (one per action, only
// beside links) and the links after the last action (only beside links and a final state).
void check_arm_readings(const Episode& e, const std::string& who) {
  const ActionKind kind = e.actions.front().kind();
  for (const Action& a : e.actions)
    if (a.kind() != kind) throw InputError(who + ": its actions are all the cup's (dvx, dvy, dw) or all joint torques, not both");
  if (kind == ActionKind::joint_torque && e.links.empty())
    throw InputError(who + ": acts in joint torques, which command an arm, and has no arm link readings");
  if (!e.joint_torques.empty()) {
    if (e.links.empty()) throw InputError(who + ": has joint torques but no arm link readings; an arm episode has both");
    if (e.joint_torques.size() != e.actions.size())
      throw InputError(who + ": " + std::to_string(e.actions.size()) + " actions and " + std::to_string(e.joint_torques.size()) +
                       " joint torque readings; there must be one per action, or none");
    for (std::size_t t = 0; t < e.joint_torques.size(); ++t) require_finite(e.joint_torques[t], who + " joint torques " + std::to_string(t));
  }
  if (!e.final_links) return;
  if (e.links.empty() || !e.final_state)
    throw InputError(who + ": has final arm links but " + (e.links.empty() ? "no arm link readings" : "no final state") +
                     "; they are known together");
  require_finite(e.final_links->angles, who + " final link angles");
  require_finite(e.final_links->rates, who + " final link rates");
}

}  // namespace

void check_episode(const Episode& e) {
  const std::string who = "episode " + (e.name.empty() ? std::string("(unnamed)") : e.name);
  if (e.states.empty()) throw InputError(who + ": has no steps");
  if (e.actions.size() != e.states.size() || e.sources.size() != e.states.size())
    throw InputError(who + ": " + std::to_string(e.states.size()) + " states, " + std::to_string(e.actions.size()) +
                     " actions and " + std::to_string(e.sources.size()) + " sources; they must be equal");
  if (!e.links.empty() && e.links.size() != e.states.size())
    throw InputError(who + ": " + std::to_string(e.states.size()) + " states and " + std::to_string(e.links.size()) +
                     " arm link readings; there must be one per state, or none");
  for (std::size_t t = 0; t < e.states.size(); ++t) {
    require_finite(e.states[t], who + " state " + std::to_string(t));
    require_finite(e.actions[t], who + " action " + std::to_string(t));
  }
  for (std::size_t t = 0; t < e.links.size(); ++t) {
    require_finite(e.links[t].angles, who + " link angles " + std::to_string(t));
    require_finite(e.links[t].rates, who + " link rates " + std::to_string(t));
  }
  check_arm_readings(e, who);
  if (!e.final_state) {
    if (!e.rewards.empty()) throw InputError(who + ": has rewards but no final state; they are known together");
    return;
  }
  require_finite(*e.final_state, who + " final state");
  if (e.rewards.size() != e.states.size())
    throw InputError(who + ": " + std::to_string(e.states.size()) + " states and " + std::to_string(e.rewards.size()) +
                     " rewards; they must be equal");
  for (std::size_t t = 0; t < e.rewards.size(); ++t)
    if (!std::isfinite(e.rewards[t])) throw InputError(who + " reward " + std::to_string(t) + " is not finite");
  if (e.terminated && e.truncated) throw InputError(who + ": both terminated and truncated");
}

}  // namespace dicestack
