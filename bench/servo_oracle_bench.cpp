// The limit of a pose-answering map on the arm: the teacher a learner distils (the tracker
// following the human recordings, as DART's defaults choose it), its every action turned into
// the map's answer (label) and back (action), with Gaussian noise of std S added to that answer
// as a regressor's error would be. Compares, in one run, the cup-space map ("/position", acting
// through the `cup` controller at every physics substep) with the joint-torque map ("/osc",
// its law's torques held through the control step). Usage:
//   dicestack_servo_oracle_bench [--starts N] [--seed S] [--noise S1,S2,...] [--maps position,osc] [--threads N]
// S is in the pose's units (world units for x and y, radians for the angle), the same for all
// three; an "/osc" map's posture answer is left as it is.
#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <dicestack/core/expert.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/features.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/record.hpp>

using namespace dicestack;

namespace {

struct Options {
  int starts = 100, threads = 0;
  std::uint64_t seed = 1000;
  std::vector<double> noise{0.0, 0.01, 0.03};
  std::vector<std::string> maps{"position", "osc"};
};

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');) out.push_back(item);
  return out;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 >= argc) throw std::runtime_error(a + " needs a value");
    const std::string v = argv[++i];
    if (a == "--starts") o.starts = std::stoi(v);
    else if (a == "--seed") o.seed = std::stoull(v);
    else if (a == "--threads") o.threads = std::stoi(v);
    else if (a == "--maps") o.maps = split(v);
    else if (a == "--noise") {
      o.noise.clear();
      for (const auto& item : split(v)) o.noise.push_back(std::stod(item));
    } else throw std::runtime_error("unknown option " + a);
  }
  return o;
}

// The teacher's action seen through `map` (label), moved by the noise, and acted on (action).
class ThroughMap final : public Policy {
 public:
  ThroughMap(std::unique_ptr<Expert> expert, const FeatureMap& map, double noise)
      : expert_(std::move(expert)), map_(map), noise_(noise) {}
  void attach(const DiceEnv& env) override { env_ = &env; }
  void reset(std::uint64_t seed) override {
    expert_->reset(seed);
    rng_ = Rng(derive_seed(seed, 11));
  }
  Action act(const History& h) override {
    const Action teacher = expert_->act(*env_);
    std::vector<double> answer(map_.outputs());
    map_.label(h, teacher, answer);
    for (std::size_t k = 0; k < kActionDim; ++k) answer[k] += noise_ * rng_.normal();
    return map_.action(h, answer);
  }
  std::string name() const override { return "teacher through " + map_.name(); }

 private:
  std::unique_ptr<Expert> expert_;
  const FeatureMap& map_;
  double noise_;
  const DiceEnv* env_ = nullptr;
  Rng rng_{0};
};

// The tracker a DART run with `features` distils (the learner's defaults), ranked with seed 0 as
// training seed 0 ranks it.
ExpertConfig teacher(const WorldConfig& world, const std::string& features, int threads) {
  const std::vector<Episode> demos =
      DemoSplit(read_demo_set(resolve_demo_set("human", world)).episodes, "episodes").train();
  const TrackerConfig tracker = learner_tracker_config(*LearnerRegistry::global().create("dart", {"expert=tracker"}), features);
  ExpertConfig config;
  config.controller = tracker.controller;
  config.retry = true;
  config.recordings = make_recordings(demos, world, tracker, 0, threads);
  return config;
}

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  WorldConfig world;
  world.embodiment = Embodiment::arm;
  std::printf("%-48s %8s %10s %8s %8s\n", "map", "noise", "success", "stacked", "walls");
  for (const std::string& target : o.maps) {
    if (target != "position" && target != "osc") throw std::runtime_error("--maps: position or osc, not " + target);
    const std::string features = target == "osc" ? "state+links+clock+start_state@dice+retry/osc" : "state+clock+start_state@dice+retry/position";
    const ExpertConfig config = teacher(world, features, o.threads);
    const FeatureMap& map = feature_map(features);
    for (const double noise : o.noise) {
      EvalRequest request;
      request.episodes = o.starts;
      request.seed = o.seed;
      request.threads = o.threads;
      request.actions = map.action_kind();
      const EvalStats s = evaluate(
          [&] { return std::make_unique<ThroughMap>(make_expert("tracker", config), map, noise); },
          world, request);
      std::printf("%-48s %8.3f %9.1f%% %7.1f%% %7.1f%%\n", features.c_str(), noise, 100 * s.realistic_success.value,
                  100 * s.stacked.value, 100 * s.wall_contact.value);
      std::fflush(stdout);
    }
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "servo_oracle_bench: %s\n", e.what());
  return 1;
}
