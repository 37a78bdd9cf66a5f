#pragma once
// How a learner's policy improves with the recordings it learns from: realistic success against
// the number of recordings, several random draws of each number (`dicestack leaderboard
// --recordings 1,3,10,68`). MimicGen and robomimic report the same curve; here it answers
// "how few recordings are enough", for DART with the tracker and for DaD.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/learners/evaluate.hpp>

namespace dicestack {

/// `k` of `episodes` drawn without replacement with `seed`, in their set's order; all of them
/// when k is at least their number. What `dataset subset` writes and the learning curve trains
/// on. Throws ConfigError for k < 1.
std::vector<Episode> draw_recordings(const std::vector<Episode>& episodes, int k, std::uint64_t seed);

/// What `dicestack leaderboard --recordings` asks for.
struct LearningCurveRequest {
  WorldConfig world;
  std::filesystem::path demos;          ///< the set the recordings are drawn from (resolve_demo_set)
  std::vector<int> recordings;          ///< how many; at or above the set's size: all of it, one draw
  int draws = 3;                        ///< draws of each number, with seeds seed, seed + 1, ...
  std::vector<std::string> learners;    ///< learner specs ("dart:expert=tracker"); empty: dart:expert=tracker and dad
  std::vector<std::string> regressors;  ///< empty: gbt
  std::vector<std::string> options;     ///< "key=value" for every learner that has the key
  int episodes = 100;                   ///< rollouts per policy
  std::uint64_t seed = 0;               ///< the first draw's seed; every policy's training and rollout seed
  int threads = 0;                      ///< 0: every core; results do not depend on it
  /// The ranks that share the work: each policy trains and rolls out collectively, as `train`
  /// and `evaluate` do; every rank returns the same curve.
  Cluster* cluster = &local_cluster();
};

/// One policy of the curve.
struct LearningCurvePoint {
  std::string learner, regressor;
  int recordings = 0;            ///< how many it learned from
  std::uint64_t draw_seed = 0;   ///< draw_recordings' seed
  std::vector<std::string> names;  ///< the recordings drawn
  int episodes = 0;
  Rate success, walls;
  double dice_in_cup = 0.0;
  double train_seconds = 0.0;
  std::string followed;          ///< the tracker's followed recordings, when it had one
};

struct LearningCurve {
  std::string header;  ///< the settings, as one line
  std::vector<LearningCurvePoint> points;
};

/// Called as each policy starts training and ends its rollouts.
using LearningCurveProgress = std::function<void(const std::string& text)>;

/// Trains every learner x regressor on every draw of every number and rolls each policy out
/// from `episodes` random starts (evaluation_start_seed(seed, i): no start a policy trained
/// from). Names, options and numbers are checked before any work (ConfigError).
LearningCurve run_learning_curve(const LearningCurveRequest& request, const LearningCurveProgress& progress = {});

/// The formats: md (a table of each learner's mean over the draws per number, then every
/// draw), csv (one line per policy), json, html (the tables and a plot, self-contained).
std::vector<std::string> learning_curve_formats();

/// The curve in `format`; throws ConfigError for another.
std::string render_learning_curve(const LearningCurve& curve, const std::string& format);

/// Writes the rendered curve to `out` atomically, replacing only a curve dicestack wrote
/// (InputError otherwise, before anything is written).
void write_learning_curve(const LearningCurve& curve, const std::string& format, const std::filesystem::path& out);

/// Throws InputError if `out` holds something other than a learning curve (checked before any work).
void check_learning_curve_replaceable(const std::filesystem::path& out);

}  // namespace dicestack
