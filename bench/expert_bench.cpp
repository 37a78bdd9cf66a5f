// Measures an expert: realistic success, stacked, dice in cup and wall contact over random starts
// (env.reset(seed) for seeds [first, first + episodes)) and from the paper's start, and the
// seconds per episode. Usage:
//   dicestack_expert_bench [expert] [episodes] [threads] [first] [budget=N] [spread=F]
//   dicestack_expert_bench [expert] --frames SEED FILE.png [EVERY]   (SEED -1: the paper's start)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/render.hpp>

using namespace dicestack;

namespace {

// A contact sheet: every `every`-th state of a trajectory, small, six to a row.
void write_strip(const std::vector<State>& states, const WorldConfig& config, int every, const std::string& path) {
  RenderOptions ro;
  ro.pixels_per_metre = 30.0;
  ro.show_hud = false;
  std::vector<Image> frames;
  for (std::size_t t = 0; t < states.size(); t += static_cast<std::size_t>(every))
    frames.push_back(render_state(states[t], config, {}, ro));
  frames.push_back(render_state(states.back(), config, {}, ro));
  const int cols = 6, w = frames[0].width, h = frames[0].height;
  const int rows = (static_cast<int>(frames.size()) + cols - 1) / cols;
  Image sheet{w * cols, h * rows, std::vector<std::uint8_t>(static_cast<std::size_t>(w * cols * h * rows * 3), 255)};
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const int r = static_cast<int>(k) / cols, c = static_cast<int>(k) % cols;
    for (int y = 0; y < h; ++y)
      std::memcpy(&sheet.bgr[(static_cast<std::size_t>(r * h + y) * static_cast<std::size_t>(sheet.width) +
                              static_cast<std::size_t>(c * w)) * 3],
                  &frames[k].bgr[static_cast<std::size_t>(y * w * 3)], static_cast<std::size_t>(w * 3));
  }
  write_png(sheet, path);
}

}  // namespace

int main(int argc, char** argv) {
  const std::string name = argc > 1 ? argv[1] : "mpc";
  const WorldConfig config;
  if (argc > 2 && std::string(argv[2]) == "--frames") {
    // --frames SEED FILE [EVERY]: a contact sheet of one episode (SEED -1 is the paper's start).
    const int seed = std::atoi(argv[3]);
    DiceEnv env(config);
    if (seed < 0) env.reset_to(paper_start_state(config)); else env.reset(static_cast<std::uint64_t>(seed));
    auto expert = make_expert(name);
    expert->reset(static_cast<std::uint64_t>(seed < 0 ? 0 : seed));
    const ExpertEpisode e = run_expert_episode(*expert, env, true);
    std::vector<State> states = e.states;
    states.push_back(env.get_state());
    write_strip(states, config, argc > 5 ? std::atoi(argv[5]) : 4, argv[4]);
    std::printf("%d steps, stacked %d, wall contact %d, realistic success %d\n", e.outcome.steps, e.outcome.stacked,
                e.outcome.wall_contact, e.outcome.realistic_success());
    return 0;
  }
  ExpertConfig ec;
  for (int i = 5; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("budget=", 0) == 0) ec.search_budget = std::atoi(arg.c_str() + 7);
    if (arg.rfind("spread=", 0) == 0) ec.search_spread = std::atof(arg.c_str() + 7);
  }
  const int episodes = argc > 2 ? std::atoi(argv[2]) : 100;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 1;
  const int first = argc > 4 ? std::atoi(argv[4]) : 0;
  // Slot 0 is the paper's start, slots 1.. the random seeds.
  std::vector<Outcome> out(static_cast<std::size_t>(episodes) + 1);
  std::vector<double> seconds(out.size());
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(out.size(), threads, [&](std::size_t i, int) {
    const auto s0 = std::chrono::steady_clock::now();
    DiceEnv env(config);
    auto expert = make_expert(name, ec);
    const std::uint64_t seed = i == 0 ? 0 : static_cast<std::uint64_t>(first) + i - 1;
    if (i == 0) env.reset_to(paper_start_state(config)); else env.reset(seed);
    expert->reset(seed);
    out[i] = run_expert_episode(*expert, env).outcome;
    seconds[i] = std::chrono::duration<double>(std::chrono::steady_clock::now() - s0).count();
  });
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  int success = 0, stacked = 0, cup = 0, touched = 0, steps = 0;
  double cpu = 0.0;
  for (std::size_t i = 1; i < out.size(); ++i) {
    success += out[i].realistic_success();
    stacked += out[i].stacked;
    cup += out[i].dice_in_cup == 3;
    touched += out[i].wall_contact;
    steps += out[i].steps;
    cpu += seconds[i];
  }
  std::printf("expert %s, seeds %d..%d, %d thread(s)\n", name.c_str(), first, first + episodes - 1, threads);
  std::printf("realistic success %d/%d, stacked %d, 3 dice in cup %d, wall contact %d, mean steps %.1f\n", success,
              episodes, stacked, cup, touched, static_cast<double>(steps) / episodes);
  std::printf("paper start: realistic success %d, stacked %d, wall contact %d, %d steps\n", out[0].realistic_success(),
              out[0].stacked, out[0].wall_contact, out[0].steps);
  std::printf("seconds per episode %.3f (one thread), wall time %.1f s\n", cpu / episodes, wall);
  std::printf("failed seeds:");
  for (std::size_t i = 1; i < out.size(); ++i)
    if (!out[i].realistic_success()) std::printf(" %d", first + static_cast<int>(i) - 1);
  std::printf("\n");
  return 0;
}
