#pragma once
// Where the paper's code (leonidk/cupdice, its DaD routine) differs from DaD as the paper
// describes it, and what DaD needs to run each difference: `faithful` switches them on, all
// ("true") or some ("start+label").
#include <memory>
#include <string>

#include <dicestack/learners/policy.hpp>

namespace dicestack {

struct CodeParts {
  bool start = false;       ///< every rollout from the one fixed start
  bool label = false;       ///< a one-step correction at every step, aimed at the recording's next state
  bool cost = false;        ///< that state's dice (poses, velocities) and the cup's velocity
  bool schedule = false;    ///< growing prefixes of each recording, several refits each; the last refit kept
  bool search = false;      ///< CMA-ES from a random point, wide, to a budget of evaluations; its best always kept
  bool duplicates = false;  ///< every refit appends every correction so far again
  bool units = false;       ///< its units: the policy's actions applied 100, 10, 0.5 times over, labels the optimiser's x
  bool any() const { return start || label || cost || schedule || search || duplicates || units; }
};

/// "false", "true" (every part) or parts joined by '+'; throws ConfigError naming an unknown part.
CodeParts code_parts(const std::string& text);

/// The paper's code applied the policy's output (in the recordings' units) times the optimiser's
/// scale again, and stored the optimiser's x (action / scale, unitless) beside the recordings'
/// actions: in SI, rollouts run actions 100, 10 and 0.5 times the policy's, and corrections are
/// labelled 0.01, 0.1 and 2 times the actions they found.
inline constexpr Action kCodeRolloutUnits{100.0, 10.0, 0.5}, kCodeLabelUnits{0.01, 0.1, 2.0};

/// The code's constants: 10 prefixes x 5 sub-iterations; CMA-ES sigma0 0.8, maxfevals 5000.
inline constexpr int kCodeWindows = 10, kCodeRefits = 5, kCodeEvaluations = 5000;
inline constexpr double kCodeSigma0 = 0.8;

/// `a` times `by`, dimension by dimension.
Action scaled(Action a, const Action& by);

/// A policy acting with the paper's code's units.
class CodeUnitsPolicy final : public Policy {
 public:
  explicit CodeUnitsPolicy(std::shared_ptr<const Model> model) : inner_(std::move(model)) {}
  Action act(const History& history) override { return scaled(inner_.act(history), kCodeRolloutUnits); }
  std::string name() const override { return inner_.name() + " in the paper's code's units"; }

 private:
  ModelPolicy inner_;
};

}  // namespace dicestack
