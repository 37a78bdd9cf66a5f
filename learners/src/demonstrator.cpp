#include <dicestack/learners/demonstrator.hpp>

#include <dicestack/core/error.hpp>

namespace dicestack {

std::vector<CupPath> cup_paths(const std::vector<Episode>& episodes) {
  std::vector<CupPath> paths;
  paths.reserve(episodes.size());
  for (const auto& e : episodes) paths.push_back({e.name, e.states, e.actions});
  return paths;
}

std::shared_ptr<const Recordings> make_recordings(const std::vector<Episode>& demos, const WorldConfig& world,
                                                  const TrackerConfig& config, std::uint64_t seed, int threads,
                                                  Cluster& cluster) {
  if (demos.empty()) throw InputError("tracker: no demonstrations to follow");
  return std::make_shared<const Recordings>(cup_paths(demos), world, config, seed, threads, cluster);
}

std::vector<ParamSpec> tracker_param_specs() {
  const TrackerConfig d;
  return {{"tracker_probes", ParamType::integer, std::to_string(d.probes), 0, 100000,
           "tracker: training starts that rank the recordings (most successes first)", {}},
          {"tracker_optimise", ParamType::boolean, d.optimise ? "true" : "false", 0, 1,
           "tracker: search timing, offset and amplitude when no recording succeeds as recorded", {}}};
}

ExpertConfig learner_expert_config(const std::string& name, const Params& params, const LearnContext& c) {
  ExpertConfig config;
  if (name == "tracker") {
    if (c.demos.empty())
      throw InputError("expert tracker: no demonstrations to follow (give a set with --demos)");
    TrackerConfig tracker;
    tracker.probes = static_cast<int>(params.integer("tracker_probes"));
    tracker.optimise = params.boolean("tracker_optimise");
    config.recordings = make_recordings(c.demos, c.world, tracker, c.seed, c.threads, *c.cluster);
  }
  return config;
}

}  // namespace dicestack
