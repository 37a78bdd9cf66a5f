// `dicestack render`: a video (or a folder of PNG frames) of a policy's rollout or of a recorded
// episode, and with --plot the paper's Fig. 2: the cup's x, the dice's x and y, the cup's angle
// and velocities over time.
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/render.hpp>
#include <dicestack/core/video.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

namespace fs = std::filesystem;
namespace si = state_index;

struct RenderOptions {
  WorldOption world;
  fs::path model, episode, out, plot;
  std::uint64_t seed = 0;
  std::string push = "none";
};

// The states to draw: a recorded episode's own states (one frame per recorded step), or a
// rollout of the model from a random start (every state, and the one after the last step).
std::vector<State> trajectory(const RenderOptions& opt, const WorldConfig& world, std::string& title) {
  if (!opt.episode.empty()) {
    title = "recorded " + opt.episode.filename().string();
    return read_episode_csv(opt.episode).states;
  }
  DiceEnv env(world);
  auto model = std::make_shared<const Model>(load_model(opt.model));
  check_map_world(model->features(), world);
  ModelPolicy p(model);
  // The first start of `evaluate --seed S`, so a rendered rollout is one that evaluate counted.
  const std::uint64_t start = evaluation_start_seed(opt.seed, 0);
  RolloutOptions options;
  options.push = initial_push_from(opt.push);
  const Episode e = rollout(env, p, random_start_state(world, start), start, StepSource::policy, options);
  const auto learner = model->record.find("learner");
  title = model->regressor().name() + " (" + (learner == model->record.end() ? "?" : learner->second) + "), seed " +
          std::to_string(opt.seed);
  std::vector<State> states = e.states;
  states.push_back(env.get_state());
  return states;
}

int run_render(const RenderOptions& opt) {
  if (opt.model.empty() == opt.episode.empty()) throw InputError("render: give exactly one of --model or --episode");
  if (opt.out.empty() && opt.plot.empty()) throw InputError("render: give --out, --plot or both");
  const WorldConfig world = opt.world.load();
  std::string title;
  const auto states = trajectory(opt, world, title);
  if (!opt.out.empty()) write_frames(states, world, title, opt.out);
  if (!opt.plot.empty()) write_png(render_plot(states, world, title), opt.plot);
  print_line("rendered " + std::to_string(states.size()) + " frames of " + title +
             (opt.out.empty() ? "" : " to " + opt.out.string()) + (opt.plot.empty() ? "" : ", plot " + opt.plot.string()));
  return 0;
}

}  // namespace

void add_render_command(CLI::App& app) {
  auto opt = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Video or frames of a rollout or a recorded episode, and the paper's Fig. 2 plot");
  opt->world.add_to(*cmd);
  cmd->add_option("--model", opt->model, "Roll this model out from a random start")->check(CLI::ExistingFile);
  cmd->add_option("--episode", opt->episode, "Replay this episode CSV's actions from its first state")->check(CLI::ExistingFile);
  cmd->add_option("--out", opt->out, "FILE.mp4, FILE.avi or FILE.gif (video; GIF via giflib), FILE.png (last frame), or a folder (one PNG per frame)");
  cmd->add_option("--plot", opt->plot, "FILE.png: cup x, dice x and y, cup angle and velocities over time");
  cmd->add_option("--seed", opt->seed, "Seed of the model's start state")->check(seed_check())->capture_default_str();
  cmd->add_option("--initial-push", opt->push, "none, left or right")->check(CLI::IsMember({"none", "left", "right"}))->capture_default_str();
  cmd->callback([opt] { run_render(*opt); });
}

}  // namespace dicestack::cli
