#pragma once
// What the iterative learners (DAgger, DaD) share: the checkpoint of a finished iteration (the
// aggregated data as a demonstration folder, then a small JSON state that points at it) and
// the measurement of a policy that goes into the learning curve.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/learners/learner.hpp>

namespace dicestack {

nlohmann::json curve_to_json(const std::vector<CurvePoint>& curve);
std::vector<CurvePoint> curve_from_json(const nlohmann::json& json);

/// Writes `data` to dir/data-<iteration>, then `state` (plus "iteration" and "data") to
/// dir/<state_file> (with "format": "dicestack-checkpoint"), both atomically and in that order,
/// then removes older data-<integer> folders that are dicestack demonstration sets (never a
/// user's data-notes/): the state always names complete data of its own iteration.
void save_checkpoint(const std::filesystem::path& dir, int iteration, nlohmann::json state, const std::string& state_file,
                     const LearnContext& context, const std::vector<Episode>& data, const std::string& description);

/// Removes DaD's earlier best-<integer>.model files in `dir` that are dicestack models, except `keep`.
void remove_old_best_models(const std::filesystem::path& dir, const std::string& keep);

/// The aggregated data a checkpoint state names.
std::vector<Episode> load_checkpoint_data(const LearnContext& context, const nlohmann::json& state);

/// What a run was started with: regressor and its settings, feature map, seed, learner options
/// but `extendable` (options a resumed run may change, e.g. DAgger's round count: more rounds
/// continue the same run). Saved in every checkpoint state under "run"; a resumed run must match it.
nlohmann::json run_settings(const LearnContext& context, const Params& learner_params,
                            const std::vector<std::string>& extendable = {});

/// The state of the last finished iteration, or null when there is none to resume from. Throws
/// InputError naming each setting that differs from the checkpoint's "run" (with both values):
/// resuming with other options would give a model that matches neither run.
nlohmann::json load_checkpoint_state(const LearnContext& context, const std::string& state_file,
                                     const nlohmann::json& run);

/// A curve point for `model`: rolled out from the held-out demonstrations' first states, or
/// from `fallback`'s when there are none.
CurvePoint measure_policy(const std::shared_ptr<const Model>& model, const LearnContext& context,
                          const std::vector<Episode>& fallback, int iteration, std::size_t rows);

}  // namespace dicestack
