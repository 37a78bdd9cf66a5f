#include <dicestack/learners/demonstrator.hpp>

#include <dicestack/datasets/features.hpp>

#include <algorithm>
#include <array>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/record.hpp>

namespace dicestack {
namespace {
constexpr std::uint64_t kRecordingsStream = 0x7265636f7264ULL;  // "record": the subset a learner follows
}  // namespace

std::vector<CupPath> cup_paths(const std::vector<Episode>& episodes) {
  std::vector<CupPath> paths;
  paths.reserve(episodes.size());
  for (const auto& e : episodes) {
    // The tracker follows a cup path: the states and the cup's velocity changes between them.
    if (!e.actions.empty() && e.actions.front().kind() != ActionKind::cup)
      throw InputError("expert tracker: recording \"" + e.name + "\" acts in joint torques; the tracker follows recordings of "
                       "the cup's actions (record them with --controller cup)");
    paths.push_back({e.name, e.states, e.actions});
  }
  return paths;
}

std::vector<Episode> pick_recordings(std::vector<Episode> episodes, int k, std::uint64_t seed) {
  if (k <= 0 || k >= static_cast<int>(episodes.size())) return episodes;
  Rng rng(seed);
  for (std::size_t i = episodes.size() - 1; i > 0; --i) std::swap(episodes[i], episodes[rng.below(i + 1)]);
  episodes.resize(static_cast<std::size_t>(k));
  return episodes;
}

std::shared_ptr<const Recordings> make_recordings(const std::vector<Episode>& demos, const WorldConfig& world,
                                                  const TrackerConfig& config, std::uint64_t seed, int threads,
                                                  Cluster& cluster, const TrackerProgress& progress) {
  if (demos.empty()) throw InputError("tracker: no demonstrations to follow");
  return std::make_shared<const Recordings>(cup_paths(demos), world, config, seed, threads, cluster, progress);
}

namespace {

// A default's text as a user types it: 4, 0.1, 0.02.
std::string number_text(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

}  // namespace

// The recordings the learners follow by default: the best-ranked one for a "/position" map,
// whose policy plays one reference with a servo (two or three references are not a smooth
// function of the start: 55.7 % against 60.2 % with one), the three best for the others (one
// path alone: 38-43 % as velocities). Measured in docs/notebook/2026-11-27-learners-page-history.md
// ("Policies from the human recordings") and docs/notebook/2026-11-27-learners-history.md
// ("Robust choices and velocity targets").
constexpr int kServoPaths = 1, kOtherPaths = 3;

// The learners' tracker preset: tuned for DART on the tuning seeds (docs/learners.md, "Policies
// from the human recordings"; the measurements: docs/notebook/2026-11-27-learners-page-history.md,
// the same section): smoothed, chosen robust to a learner's errors, narrowed before
// warped where none succeeds as recorded (in the dice frame 80.8 -> 83.0 %, and a 3x faster
// search), each recording's smoothing chosen among variants (from 3 recordings 36 -> 81 %).
constexpr const char* kLearnerPreset = "distill";

std::vector<ParamSpec> tracker_param_specs() {
  const TrackerConfig d = tracker_preset(kLearnerPreset);
  return {{"tracker_preset", ParamType::choice, kLearnerPreset, 0, 0,
           "tracker: the named settings the other tracker_* options change (distill: tuned for a learner, the "
           "defaults shown; plain: the tracker of record and robustness)",
           tracker_preset_names()},
          {"tracker_probes", ParamType::integer, std::to_string(d.probes), 0, 100000,
           "tracker: training starts that rank the recordings (most successes first; with a map in joint torques at least 32 unless given)", {}},
          {"tracker_optimise", ParamType::boolean, d.optimise ? "true" : "false", 0, 1,
           "tracker: search timing, offset and amplitude when no recording succeeds as recorded", {}},
          {"tracker_paths", ParamType::integer, "-1", -1, 1000000,
           "tracker: follow only this many recordings, those that succeed from the most probe starts (0: all; "
           "-1: 1 with a /position or /osc map, else 3)", {}},
          {"tracker_demos", ParamType::text, "same", 0, 0,
           "tracker: follow the training episodes of this set (builtin, human or a folder; same: the run's --demos)", {}},
          {"tracker_recordings", ParamType::integer, "0", 0, 1000000,
           "tracker: follow only this many of the demonstrations, drawn with the seed (0: all)", {}},
          {"tracker_smooth", ParamType::real, number_text(d.smooth), 0, 1000,
           "tracker: smooth each path by a Gaussian of this std in steps before following it (0: as recorded)", {}},
          {"tracker_rescue", ParamType::integer, std::to_string(d.rescue), 0, 100000,
           "tracker: every this many steps, check the path's rest still succeeds and join another recording "
           "midway when not (0: choose once per episode)", {}},
          {"tracker_robust", ParamType::integer, std::to_string(d.robust), 0, 1000,
           "tracker: noisy trials a choice must also pass, and that rank the recordings (0: off)", {}},
          {"tracker_robust_noise", ParamType::real, number_text(d.robust_noise), 0, 10,
           "tracker: the std of those trials' executed-action noise, as a fraction of action.scale", {}},
          {"tracker_robust_warp", ParamType::real, number_text(d.robust_warp), 0, 1,
           "tracker: std of each noisy trial's random warp (time scale, offset m, amplitude; 0: none)", {}},
          {"tracker_keep_extremes", ParamType::boolean, d.keep_extremes ? "true" : "false", 0, 1,
           "tracker: narrow a moved path's swing to reach no further than the recording's", {}},
          {"tracker_shrink", ParamType::integer, std::to_string(d.shrink), 0, 100,
           "tracker: when no recording succeeds as recorded, first narrow the swing in this many even steps, then CMA-ES (0: CMA-ES only)", {}},
          {"tracker_variants", ParamType::boolean, d.variants.empty() ? "false" : "true", 0, 1,
           "tracker: also rank the 8 best-ranked recordings smoothed by each of 0, 1, 2, 3, 4, 6 and 8 steps, score "
           "the 4 best paths again from 4 x tracker_probes more probe starts, and follow the best", {}},
          {"tracker_refine", ParamType::integer, std::to_string(d.refine), 0, 10000,
           "tracker: CMA-ES generations that move the leading path by smooth offsets to succeed from the most "
           "starts, clean and under DART's noise; the refined path leads if it beats the leading path from fresh starts (0: off; "
           "with a map in joint torques 0 unless given)", {}},
          {"tracker_refine_probes", ParamType::integer, std::to_string(d.refine_probes), 1, 100000,
           "tracker: starts per generation of tracker_refine", {}},
          {"tracker_refine_restarts", ParamType::integer, std::to_string(d.refine_restarts), 1, 100,
           "tracker: refinements at most, each of the next path of the ranking (the leader first, wrapping) from a seed "
           "of its own, until one succeeds in " + number_text(100.0 * d.refine_enough) + " % of its validation trials; "
           "the best from the same fresh starts leads if it beats the leading path", {}},
          {"tracker_refine_timing", ParamType::real, number_text(d.refine_range[3]), 0, 1,
           "tracker: tracker_refine also moves the path's timing, each bump by at most this many seconds (0: not)", {}}};
}

std::string followed_recordings(const Recordings& recordings, std::size_t most) {
  std::string out;
  for (const std::size_t p : recordings.order()) {
    if (most-- == 0) return out.empty() ? "..." : out + ", ...";
    // A path with trials was ranked by them (or, refined, validated); without, it was not ranked.
    const int trials = recordings.probe_trials()[p];
    out += (out.empty() ? "" : ", ") + recordings.paths()[p].name;
    out += trials > 0 ? " (" + std::to_string(recordings.probe_successes()[p]) + " of " + std::to_string(trials) +
                            " probe trials)"
                      : " (not ranked)";
  }
  return out;
}

bool servo_targets(const std::string& features) {
  const ActionTarget target = feature_map(features).target();
  return target == ActionTarget::position || target == ActionTarget::osc;
}

bool expert_retries(const std::string& retry, const std::string& features) {
  return retry == "auto" ? feature_map(features).attempts() : retry == "true";
}

ParamSpec retry_param_spec() {
  return {"retry", ParamType::choice, "auto", 0, 0,
          "mpc and tracker: once a failed attempt has come to rest, start afresh from there (auto: with a +retry feature map)",
          {"auto", "true", "false"}};
}

int tracker_paths_for(int paths, const std::string& features) {
  if (paths >= 0) return paths;
  return servo_targets(features) ? kServoPaths : kOtherPaths;
}

TrackerConfig learner_tracker_config(const Learner& learner, const std::string& features) {
  const Params& params = learner.params();
  const std::string& preset = params.choice("tracker_preset");
  TrackerConfig tracker = tracker_preset(preset);
  // The options given set the preset's settings of their name; "paths" -1 is the map's count.
  std::map<std::string, std::string> text(params.as_text().begin(), params.as_text().end());
  for (const auto& setting : tracker_setting_names()) {
    const std::string key = "tracker_" + setting;
    if (setting == "paths" || !learner.given(key)) continue;
    set_tracker_setting(tracker, setting, text.at(key));
  }
  const int paths = static_cast<int>(params.integer("tracker_paths"));
  if (learner.given("tracker_paths") || preset == kLearnerPreset) tracker.paths = tracker_paths_for(paths, features);
  tracker.controller = feature_map(features).action_kind();  // paths chosen in the controller the labels are for
  // Refining a path in held torques costs 40 min for the preset's refinements, and with 16
  // probe starts a weaker path led for one training seed in three (199 of 480 probe trials
  // against 606 of 960 with 32; that run took 406 s instead of 285 s).
  if (tracker.controller == ActionKind::joint_torque)
    settle_for_joint_torques(tracker, [&](std::string_view s) { return learner.given("tracker_" + std::string(s)); });
  validate(tracker);
  return tracker;
}

std::vector<std::pair<std::string, std::string>> effective_options(const Learner& learner) {
  std::vector<std::pair<std::string, std::string>> out = learner.params().as_text();
  std::string preset;
  for (const auto& [key, value] : out)
    if (key == "tracker_preset") preset = value;
  if (preset.empty() || preset == kLearnerPreset) return out;  // no tracker options, or their defaults are the preset's
  const TrackerConfig c = tracker_preset(preset);
  for (auto& [key, value] : out) {
    if (!key.starts_with("tracker_") || learner.given(key)) continue;
    const std::string setting = key.substr(8);
    const auto& names = tracker_setting_names();
    if (std::find(names.begin(), names.end(), setting) != names.end()) value = tracker_setting_text(c, setting);
  }
  return out;
}

ExpertConfig learner_expert_config(const std::string& name, const Learner& learner, const LearnContext& c) {
  ExpertConfig config;
  config.controller = feature_map(c.features).action_kind();  // labels in the actions the map answers
  const Params& params = learner.params();
  if (name == "tracker") {
    const TrackerConfig tracker = learner_tracker_config(learner, c.features);
    // Another set's training episodes (the episode split's), as --demos would give them.
    const std::string& other = params.choice("tracker_demos");
    const std::vector<Episode> own =
        other == "same" ? c.demos : DemoSplit(read_demo_set(resolve_demo_set(other, c.world)).episodes, "episodes").train();
    if (own.empty()) throw InputError("expert tracker: no demonstrations to follow (give a set with --demos)");
    const auto followed = pick_recordings(own, static_cast<int>(params.integer("tracker_recordings")),
                                          derive_seed(c.seed, kRecordingsStream));
    // The paths' preparation can take minutes (ranking, refinements): it is shown as a phase.
    TrackerProgress shown;
    if (c.progress)
      shown = [&c](const std::string& stage, int done, int total) { c.progress({"tracker: " + stage, 0, 0, 0, 0, done, total, 0.0}); };
    config.recordings = make_recordings(followed, c.world, tracker, c.seed, c.threads, *c.cluster, shown);
  }
  return config;
}

}  // namespace dicestack
