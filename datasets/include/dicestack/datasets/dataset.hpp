#pragma once
// Demonstrations as matrices a regressor can fit: X (N x a feature map's width; the 24 state
// numbers by default), Y (N x 3 actions), with episode boundaries, and the train/test splits of DESIGN.
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <dicestack/core/matrix.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/datasets/features.hpp>

namespace dicestack {

/// Stacked (state, action) pairs of some episodes.
struct Dataset {
  Matrix x;                              ///< N x features.width() (24 for "state")
  Matrix y;                              ///< N x features.outputs() (3; 4 for a "/torque" or "/osc" map)
  std::vector<std::size_t> episode_begin;  ///< first row of each episode, ascending
  std::vector<std::string> episode_names;

  std::size_t rows() const { return static_cast<std::size_t>(x.rows()); }
  std::size_t episodes() const { return episode_begin.size(); }
};

/// Which steps of an episode are rows: all when empty. The others are history only (DaD's
/// corrections carry the rollout before them so that a map reads their whole episode).
using RowFilter = std::function<bool(const Episode& episode, std::size_t step)>;

/// Throws InputError naming the episode if `features` cannot make its rows: a map of the arm's
/// links on an episode without them, or labels of another controller's actions (make_dataset's
/// check, for callers that check before other work).
void check_rows_of(const Episode& episode, const FeatureMap& features);

/// Stacks the episodes in the given order; row t of an episode is `features` of its history up
/// to step t, for every t `rows` keeps. Throws InputError if an episode is malformed.
Dataset make_dataset(const std::vector<Episode>& episodes, const FeatureMap& features = state_features(),
                     const RowFilter& rows = {});

/// A train/test partition and how it was made (for reports).
struct Split {
  Dataset train;
  Dataset test;
  std::string description;  ///< e.g. "episodes: i % 5 == 4 is test (14 of 68)"
};

/// DESIGN's default split rule: episode i (in file-name order) is a test episode when i % 5 == 4.
bool is_test_episode(std::size_t index);

/// DESIGN's default: episode i (in file-name order) is a test episode when i % 5 == 4.
/// Throws InputError if that leaves no training episode.
Split split_by_episode(const std::vector<Episode>& episodes, const FeatureMap& features = state_features());

/// The paper's Table I protocol: a random `test_fraction` of rows is test, drawn as
/// scikit-learn's train_test_split(random_state=seed) draws it (numpy's legacy Mersenne
/// Twister permutation), so neighbouring frames of one episode can sit on both sides.
Split split_by_rows(const std::vector<Episode>& episodes, double test_fraction = 0.25, std::uint32_t seed = 42,
                    const FeatureMap& features = state_features());

/// A demonstration set split for an experiment, seen both ways: the episodes a learner trains
/// on (and those it may hold out), and the same split as matrices for eq. 9's errors.
class DemoSplit {
 public:
  /// `rule`: "episodes" (i % 5 == 4 is test), "rows" (the paper's random 25 % of rows; a learner
  /// gets the training rows as one pseudo-episode, as the paper fitted on shuffled rows) or
  /// "none" (everything is training). Throws ConfigError for another rule, InputError when the
  /// split leaves nothing to train on.
  DemoSplit(const std::vector<Episode>& episodes, const std::string& rule);

  const std::string& rule() const { return rule_; }
  /// What a learner trains on: the training episodes, or (rows) one pseudo-episode of the rows.
  const std::vector<Episode>& train() const { return train_; }
  /// The test episodes under "episodes"; empty under "rows" and "none".
  const std::vector<Episode>& held_out() const { return held_out_; }
  /// The split's matrices through `features`, made once per map (not thread-safe). Under "rows"
  /// only the state map: ConfigError for a map that reads an episode's history.
  const Split& matrices(const FeatureMap& features = state_features()) const;
  /// What matrices().description says, without making rows (a set whose actions the state map
  /// does not answer, such as joint torques, has none of its rows).
  std::string description() const;

 private:
  std::vector<Episode> all_, train_, held_out_;
  std::string rule_;
  mutable std::map<std::string, std::unique_ptr<Split>> matrices_;
};

/// numpy.random.RandomState(seed).permutation(n), reproduced exactly.
std::vector<std::size_t> numpy_legacy_permutation(std::size_t n, std::uint32_t seed);

}  // namespace dicestack
