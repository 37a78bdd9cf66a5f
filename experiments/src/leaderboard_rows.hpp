#pragma once
// One leaderboard job, apart from the dealing and the table: a learner row trained and rolled
// out for one training seed, or a baseline built and rolled out; how a row adds its seeds up;
// and the bytes jobs travel in between ranks. (Each job's estimated cost is declared in
// leaderboard.hpp.)
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/leaderboard.hpp>
#include <dicestack/experiments/profile.hpp>

namespace dicestack {

/// What every row of a run shares.
struct RowSettings {
  WorldConfig world;
  const Profile* profile = nullptr;
  const DemoSplit* split = nullptr;  ///< learners train on its episodes; errors on its matrices
  int episodes = 20;                 ///< evaluation rollouts per training seed
  int seeds = 1;                     ///< training seeds per row
  std::uint64_t seed = 0;            ///< the first training seed, and the rollouts' starts
  int threads = 0;
  Perturbation perturbation;  ///< the rollouts' worlds, drawn per episode
  std::string estimator;  ///< what the rollouts' policies are shown under sensing factors (empty: each model's own)
  bool previews = false;      ///< keep each row's first successful and first failed rollout whole
  /// The options a learner runs with (the profile's, then the user's).
  std::function<std::vector<std::string>(const std::string& learner)> learner_options;
};

/// A step of the run: (text, fraction of the whole run, milestone).
using RowReport = std::function<void(const std::string& text, double fraction, bool milestone)>;

/// A learner row's measurements for one training seed.
struct SeedResult {
  double fit_s = 0.0, train_error = 0.0, test_error = 0.0;
  bool has_test = false;
  EvalStats stats;
  std::vector<EpisodeResult> results;  ///< each rollout's, in index order
  std::vector<RowPreview> success_preview, failure_preview;  ///< when RowSettings::previews
};
std::string pack_seed_result(const SeedResult& r);
SeedResult unpack_seed_result(std::string_view bytes);
void pack_row(Packer& p, const LeaderboardRow& r);
LeaderboardRow unpack_row(Unpacker& u);

/// Adds rollouts' outcomes to a row: counts summed, means divided by the row's `seeds`.
void add_outcomes(LeaderboardRow& row, const EvalStats& stats, int seeds);

/// Adds one training seed's rollouts to a row: their results, and its previews where the row
/// has none yet.
void add_rollouts(LeaderboardRow& row, std::uint64_t training_seed, const std::vector<EpisodeResult>& results,
                  const std::vector<RowPreview>& success, const std::vector<RowPreview>& failure);

/// An evaluation request's outputs for a row's seed: `results` always, `episodes` when previews are kept.
void keep_rollouts(EvalRequest& request, bool previews, std::vector<EpisodeResult>& results, std::vector<Episode>& episodes);

/// The first successful and the first failed of `episodes` (rolled out by `training_seed`), whole.
void pick_previews(const std::vector<Episode>& episodes, std::uint64_t training_seed, std::vector<RowPreview>& success,
                   std::vector<RowPreview>& failure);

class RowRunner {
 public:
  /// Both are kept by reference and must outlive the runner.
  RowRunner(const RowSettings& settings, const RowReport& report) : s_(settings), report_(report) {}

  /// Seed `seed_index` (0-based) of a learner row, named `row_text` in progress ("[2/17] bc
  /// knn"), its work shared over `inner`; its progress runs from `from` to `from + span`.
  SeedResult learner_seed(const std::string& learner, const std::string& features, const std::string& regressor,
                          int seed_index, const std::string& row_text, Cluster& inner, double from, double span) const;
  /// A baseline optimised (or learned) with the profile's budget, rolled out for every seed.
  LeaderboardRow baseline_row(const std::string& name, Cluster& inner, double from, double span) const;
  /// A learner row from its seeds' results, added up in seed order (the same sums for any deal).
  LeaderboardRow combine(const std::string& learner, const std::string& features, const std::string& regressor,
                         const std::vector<SeedResult>& seeds) const;

 private:
  const RowSettings& s_;
  const RowReport& report_;
};

}  // namespace dicestack
