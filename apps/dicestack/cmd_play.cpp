// `dicestack play`: the interactive game (arrows force, q/e torque, m mouse aim, r reset,
// s save and start over, p screenshot, Escape quits).
#include <cstdio>

#include "cli.hpp"
#include "options.hpp"
#include "player.hpp"

namespace dicestack::cli {
namespace {

struct PlayCommand {
  WorldOption world;
  PlayOptions play;
  std::string start = "random";
};

int run_play(PlayCommand& cmd) {
  cmd.play.world = cmd.world.load();
  cmd.play.paper_start = cmd.start == "paper";
  const PlayReport r = play(cmd.play);
  char line[256];
  std::snprintf(line, sizeof line,
                "played %ld frames in %.1f s (%.1f frames/s; drawing %.2f ms, physics %.3f ms per frame)%s",
                r.frames, r.seconds, r.frames / std::max(r.seconds, 1e-9), r.render_ms, r.physics_ms,
                cmd.play.record.empty() ? ""
                                        : (", recorded " + std::to_string(r.episodes_recorded) + " episodes into " +
                                           cmd.play.record.string()).c_str());
  print_line(line);
  return 0;
}

}  // namespace

void add_play_command(CLI::App& app) {
  auto cmd = std::make_shared<PlayCommand>();
  CLI::App* sub = app.add_subcommand(
      "play",
      "Play the game in a window: arrows push the cup (released keys stop it), q/e turn it, m toggles mouse aim,\n"
      "r discards the episode and starts over, s saves it and starts over, p saves a screenshot, Escape saves and quits;\n"
      "episodes that end (success or time limit) are saved too");
  cmd->world.add_to(*sub);
  sub->add_option("--record", cmd->play.record, "Append every episode to this demonstration folder");
  sub->add_option("--seed", cmd->play.seed, "Seed of the first start state")->check(seed_check())->capture_default_str();
  sub->add_option("--start", cmd->start, "Start state: random (from the seed) or paper")
      ->check(CLI::IsMember({"random", "paper"}))
      ->capture_default_str();
  sub->add_option("--scale", cmd->play.scale, "Window size relative to 900 x 700")
      ->check(CLI::Range(0.25, 4.0))
      ->capture_default_str();
  sub->add_option("--screenshot-dir", cmd->play.screenshot_dir, "Folder for screenshots taken with p");
  sub->add_option("--max-seconds", cmd->play.max_seconds, "Quit after this many seconds (0: never)")
      ->check(CLI::NonNegativeNumber);
  sub->callback([cmd] { run_play(*cmd); });
}

}  // namespace dicestack::cli
