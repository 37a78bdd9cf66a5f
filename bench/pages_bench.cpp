// Results pages at scale: writes a leaderboard page of ROWS rows (default 40), each with
// 100 rollouts' results and two previews (a built-in demonstration that stacks, and a rollout
// of the zero action), and prints the time to write it, the page's size and the media's.
// bench/pages_bench.py then loads it in headless Chromium and measures the first render.
//
//   dicestack_pages_bench OUT.html [ROWS]
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include <dicestack/core/env.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/experiments/leaderboard.hpp>
#include <dicestack/experiments/train.hpp>

namespace fs = std::filesystem;
using namespace dicestack;

namespace {

std::uintmax_t folder_bytes(const fs::path& dir) {
  std::uintmax_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) n += e.file_size();
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: dicestack_pages_bench OUT.html [ROWS]\n");
    return 2;
  }
  try {
    const fs::path out = argv[1];
    const int rows = argc > 2 ? std::stoi(argv[2]) : 40;
    const WorldConfig world;
    const DemoSet set = read_demo_set(resolve_demo_set("builtin", world));
    DiceEnv env(world);
    Leaderboard board;
    board.world = world;
    board.header = "pages bench: " + std::to_string(rows) + " synthetic rows";
    board.meta_json = R"({"bench": "pages", "rows": )" + std::to_string(rows) + "}";
    for (int r = 0; r < rows; ++r) {
      LeaderboardRow row{"regressor" + std::to_string(r), r % 2 ? "dart" : "bc", "state"};
      row.train_error = 0.1 * r;
      row.test_error = 0.2 * r;
      for (int i = 0; i < 100; ++i) {
        EpisodeResult e;
        e.index = i;
        e.seed = static_cast<std::uint64_t>(r * 1000 + i);
        e.success = e.stacked = (i + r) % 3 == 0;
        e.wall_contact = !e.success && i % 2;
        e.wall_step = e.wall_contact ? 100 : -1;
        e.dice_in_cup = 3;
        e.length = 300;
        row.rollouts.push_back({0, e});
        row.episodes += 1;
        row.success += e.success;
        row.stacked += e.stacked;
        row.walls += e.wall_contact;
      }
      const Episode& demo = set.episodes[static_cast<std::size_t>(r) % set.episodes.size()];
      row.success_preview.push_back({0, 0, demo.seed, demo.states});
      RowPreview failure{0, 1, static_cast<std::uint64_t>(r), {}};
      failure.states.push_back(env.reset_to(random_start_state(world, static_cast<std::uint64_t>(r)), 0));
      for (int t = 0; t < 300; ++t) failure.states.push_back(env.step({0.0, 0.0, 0.0}).observation);
      row.failure_preview.push_back(std::move(failure));
      board.rows.push_back(std::move(row));
    }
    const auto t0 = std::chrono::steady_clock::now();
    write_leaderboard(board, "html", out);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const fs::path media = out.parent_path() / (out.stem().string() + "_files");
    std::printf("rows %d: written in %.2f s; page %.1f kB; media %.1f MB (%zu previews)\n", rows, seconds,
                static_cast<double>(fs::file_size(out)) / 1e3, static_cast<double>(folder_bytes(media)) / 1e6,
                static_cast<std::size_t>(2 * rows));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "pages bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
