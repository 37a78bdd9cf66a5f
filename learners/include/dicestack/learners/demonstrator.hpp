#pragma once
// The demonstrator made of demonstrations: a demonstration set turned into the
// tracker expert's Recordings (core/tracker.hpp), for record, DART, DAgger, the leaderboard and
// Python.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/tracker.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/learners/learner.hpp>

namespace dicestack {

/// Each episode's states and actions as a cup path named after the episode.
std::vector<CupPath> cup_paths(const std::vector<Episode>& episodes);

/// `k` of `episodes` drawn without replacement with `seed` (all of them when k is 0 or not
/// smaller than their number), in the order drawn: the ablation "from k recordings".
std::vector<Episode> pick_recordings(std::vector<Episode> episodes, int k, std::uint64_t seed);

/// The tracker's recordings from `demos` (ranked by simulation from config.probes training
/// starts of `seed`: see Recordings; `progress` as there). Throws InputError if `demos` is empty.
/// Collective over `cluster`.
std::shared_ptr<const Recordings> make_recordings(const std::vector<Episode>& demos, const WorldConfig& world,
                                                  const TrackerConfig& config, std::uint64_t seed, int threads = 0,
                                                  Cluster& cluster = local_cluster(), const TrackerProgress& progress = {});

/// The recordings the tracker follows, best-ranked first, each with its probe score:
/// "episode_0039 (88 of 96 probe trials), ..." ("not ranked" with no probes). A learner's model
/// records it as "tracker_followed": which recording a policy plays, and how robust it was.
/// With `most`, only the first `most`, then ", ..." if there are more.
std::string followed_recordings(const Recordings& recordings, std::size_t most = SIZE_MAX);

/// True when the feature map `features` answers a cup pose to servo to ("/position", "/osc"): the
/// tracker's labels are then one pose per step, and the learners follow one recording
/// (docs/learners.md, "Position targets").
bool servo_targets(const std::string& features);

/// Whether a learner's expert tries again after a failed attempt (ExpertConfig::retry), for the
/// option value `retry`: "auto" when `features` is a "+retry" map (whose clock and start restart
/// with each attempt, as the expert's choices do), else "true" or "false" as given.
bool expert_retries(const std::string& retry, const std::string& features);

/// The `retry` option of the learners whose expert may try again (DART, DAgger): auto, true or
/// false, read by expert_retries.
ParamSpec retry_param_spec();

/// How many recordings a learner's tracker follows for the option value `paths`: -1 is the
/// default for the feature map `features` (1 for a "/position" or "/osc" map, else 3); others as given.
int tracker_paths_for(int paths, const std::string& features);

/// The options of a learner whose expert may be the tracker (DART, DAgger, DaD): tracker_preset,
/// then "tracker_" + each tracker setting (tracker_setting_names: the TrackerConfig fields of that
/// name, their defaults the preset's), tracker_demos and tracker_recordings (follow only that
/// many of the demonstrations, drawn with the run's seed).
std::vector<ParamSpec> tracker_param_specs();

/// The tracker a learner's options ask for: the preset `tracker_preset`, each tracker_* option
/// given set on top (by the setting of its name, tracker_setting_names), and `tracker_paths` -1
/// resolved for the feature map `features` (with the learners' preset or when given).
/// Throws ConfigError as tracker_config.
TrackerConfig learner_tracker_config(const Learner& learner, const std::string& features);

/// The learner's options as text, each tracker_* option not given shown as its preset's value
/// (under tracker_preset=distill, the defaults themselves): what checkpoints compare and models
/// record, so that two runs with the same text ran the same tracker.
std::vector<std::pair<std::string, std::string>> effective_options(const Learner& learner);

/// The ExpertConfig of a learner's expert `name` (DART, DAgger, DaD): for "tracker", its
/// recordings made from the context's training demonstrations with learner_tracker_config
/// (ranked with the context's seed, over its cluster); for the others, the defaults. Throws
/// InputError for "tracker" without demonstrations.
ExpertConfig learner_expert_config(const std::string& name, const Learner& learner, const LearnContext& context);

}  // namespace dicestack
