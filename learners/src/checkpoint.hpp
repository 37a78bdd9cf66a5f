#pragma once
// What the iterative learners (DAgger, DaD) share: the checkpoint of a finished iteration (the
// aggregated data as a demonstration folder, then a small JSON state that points at it) and
// the measurement of a policy that goes into the learning curve.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/learners/learner.hpp>

namespace dicestack {

nlohmann::json curve_to_json(const std::vector<CurvePoint>& curve);

/// Writes `data` to dir/data-<iteration>, then `state` (plus "format": "dicestack-checkpoint",
/// "version", "iteration" and "data") to dir/<state_file>, both atomically and in that order,
/// then removes older data-<integer> folders that are dicestack demonstration sets (never a
/// user's data-notes/): the state always names complete data of its own iteration.
void save_checkpoint(const std::filesystem::path& dir, int iteration, nlohmann::json state, const std::string& state_file,
                     const LearnContext& context, const std::vector<Episode>& data, const std::string& description);

/// Removes DaD's earlier best-<integer>.model files in `dir` that are dicestack models, except `keep`.
void remove_old_best_models(const std::filesystem::path& dir, const std::string& keep);

/// What a run was started with: regressor and its settings (every schema parameter's parsed value,
/// so "max_depth=08" and "max_depth=8" are one setting), feature map, seed, learner options (effective_options: as the run uses them) but
/// `extendable` (options a resumed run may change, e.g. DAgger's round count: more rounds continue
/// the same run). Saved in every checkpoint state under "run"; a resumed run must match it.
/// Throws ConfigError for an unknown regressor or a bad setting.
nlohmann::json run_settings(const LearnContext& context, const std::vector<std::pair<std::string, std::string>>& learner_options,
                            const std::vector<std::string>& extendable = {});

/// A checkpoint state as read back: the common fields checked, the learner's own fields read
/// through checked accessors that throw InputError naming the file and the field.
class CheckpointState {
 public:
  CheckpointState(std::filesystem::path path, nlohmann::json json);

  int iteration() const { return iteration_; }
  const std::vector<CurvePoint>& curve() const { return curve_; }
  /// The aggregated data the state names (dir/data-<iteration>).
  std::vector<Episode> data() const;

  std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi) const;
  double number(const std::string& key) const;
  /// A file name inside the checkpoint folder (no separator, not "." or "..").
  std::filesystem::path file(const std::string& key) const;

 private:
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

  std::filesystem::path path_;
  nlohmann::json json_;
  int iteration_ = 0;
  std::vector<CurvePoint> curve_;
};

/// The state of the last finished iteration, or nothing when there is none to resume from.
/// Throws InputError for a state that is not ours, of a newer version or malformed, and naming
/// each setting that differs from the checkpoint's "run" (with both values; regressor parameters
/// and learner options compared one by one, as parsed values): resuming with other options
/// would give a model that matches neither run.
std::optional<CheckpointState> load_checkpoint_state(const LearnContext& context, const std::string& state_file,
                                                     const nlohmann::json& run);

/// A curve point for `model`: rolled out from the held-out demonstrations' first states, or
/// from `fallback`'s when there are none.
CurvePoint measure_policy(const std::shared_ptr<const Model>& model, const LearnContext& context,
                          const std::vector<Episode>& fallback, int iteration, std::size_t rows);

}  // namespace dicestack
