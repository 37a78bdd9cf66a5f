// Does the expert recover from the states a learned policy leads it to? The policy acts for k
// steps while the expert watches (it is asked every step, so its plan and latches follow the
// episode, as DAgger asks it), then the expert takes over. Prints, per k, the realistic success
// from evaluation starts and how far the policy's actions were from the expert's labels.
//   dicestack_handover_bench MODEL [--expert mpc|scripted|tracker] [--demos builtin|human|DIR] [--replan]
//                            [--episodes N] [--seed S]
// The tracker follows the recordings of --demos (default: the human recordings).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/demonstrator.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/policy.hpp>
#include <dicestack/experiments/train.hpp>

using namespace dicestack;

namespace {

// The model acts for the first k steps, the expert after; the expert is asked every step (its
// plan and latches follow the episode, as DAgger asks it), and `gap` sums how far the model's
// actions were from its labels (in units of action.scale).
class Handover final : public Policy {
 public:
  Handover(Expert& expert, const DiceEnv& env, const Model& model, int k)
      : expert_(expert, env), model_(model), k_(k), scale_(env.config().action.scale) {}
  void attach(const DiceEnv& env) override { expert_.attach(env); }
  void reset(std::uint64_t seed) override { expert_.reset(seed); }
  Action act(const History& h) override {
    const Action label = expert_.act(h);
    if (static_cast<int>(h.t()) >= k_) return label;
    const Action a = model_.act(h);
    for (std::size_t j = 0; j < kActionDim; ++j) gap += std::abs(a[j] - label[j]) / scale_[j];
    ++steps;
    return a;
  }
  std::string name() const override { return "handover"; }

  double gap = 0.0;
  long steps = 0;

 private:
  ExpertPolicy expert_;
  const Model& model_;
  int k_;
  std::array<double, kActionDim> scale_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: dicestack_handover_bench MODEL [--expert NAME] [--demos SET] [--replan] [--episodes N] "
                         "[--seed S]\n");
    return 2;
  }
  std::string expert_name = "mpc", demos = "human";
  bool replan = false;
  int episodes = 100;
  std::uint64_t seed = 1000;
  try {
    auto number = [](const std::string& text) {
      if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
        throw std::invalid_argument("expected a whole number, got \"" + text + "\"");
      return std::stoull(text);
    };
    for (int i = 2; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--expert" && i + 1 < argc) expert_name = argv[++i];
      else if (a == "--demos" && i + 1 < argc) demos = argv[++i];
      else if (a == "--replan") replan = true;
      else if (a == "--episodes" && i + 1 < argc) episodes = static_cast<int>(std::min(number(argv[++i]), 1000000ULL));
      else if (a == "--seed" && i + 1 < argc) seed = number(argv[++i]);
      else throw std::invalid_argument("unknown argument " + a);
    }
    const auto model = std::make_shared<const Model>(load_model(argv[1]));
    const WorldConfig world;
    ExpertConfig config;
    config.replan = replan;
    if (expert_name == "tracker")
      config.recordings = make_recordings(read_demo_set(resolve_demo_set(demos, world)).episodes, world, {}, seed);
    std::printf("model %s, expert %s (%s), %d evaluation starts from seed %llu\n", argv[1], expert_name.c_str(),
                replan ? "replanning" : "planning once", episodes, static_cast<unsigned long long>(seed));
    std::printf("%12s %10s %8s %24s\n", "policy steps", "success", "walls", "|policy - label| / scale");
    for (const int k : {0, 30, 60, 90, 120, 150, 180, 210, std::numeric_limits<int>::max()}) {
      std::vector<int> success(static_cast<std::size_t>(episodes)), walls(success.size());
      std::vector<double> gap(success.size());
      std::vector<long> steps(success.size());
      parallel_for(success.size(), 0, [&](std::size_t i, int) {
        DiceEnv env(world);
        auto expert = make_expert(expert_name, config);
        Handover policy(*expert, env, *model, k);
        const std::uint64_t s = evaluation_start_seed(seed, i);
        const Episode e = rollout(env, policy, random_start_state(world, s), s, StepSource::policy);
        success[i] = e.outcome.realistic_success();
        walls[i] = e.outcome.wall_contact;
        gap[i] = policy.gap;
        steps[i] = policy.steps;
      });
      double g = 0.0;
      long n = 0, ok = 0, wall = 0;
      for (std::size_t i = 0; i < success.size(); ++i) g += gap[i], n += steps[i], ok += success[i], wall += walls[i];
      std::printf("%12s %9.0f%% %7.0f%% %24.3f\n", k == std::numeric_limits<int>::max() ? "all" : std::to_string(k).c_str(),
                  100.0 * ok / episodes, 100.0 * wall / episodes, n ? g / n : 0.0);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dicestack_handover_bench: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
