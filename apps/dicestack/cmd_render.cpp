// `dicestack render`: a video (or a folder of PNG frames) of a policy's rollout or of a recorded
// episode, and with --plot the paper's Fig. 2: the cup's x, the dice's x and y, the cup's angle
// and velocities over time.
#include <cmath>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/render.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/evaluate.hpp>

#include "cli.hpp"
#include "options.hpp"
#include "video.hpp"

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

// Fig. 2: stacked panels over time.
void write_plot(const std::vector<State>& states, const WorldConfig& world, const std::string& title, const fs::path& out) {
  struct Series {
    std::string name;
    std::vector<std::size_t> columns;
    std::vector<std::string> labels;
  };
  const std::vector<Series> panels{
      {"cup x (m)", {si::kCupX}, {"cup"}},
      {"dice x (m)", {si::die(0), si::die(1), si::die(2)}, {"die 0", "die 1", "die 2"}},
      {"dice y (m)", {si::die(0) + 1, si::die(1) + 1, si::die(2) + 1}, {"die 0", "die 1", "die 2"}},
      {"cup angle (rad)", {si::kCupAngle}, {"cup"}},
      {"cup velocity", {si::kCupVx, si::kCupVy, si::kCupW}, {"vx (m/s)", "vy (m/s)", "w (rad/s)"}}};
  const int width = 1000, panel_h = 170, margin = 60, top = 40;
  cv::Mat img(top + panel_h * static_cast<int>(panels.size()) + 40, width, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(img, title, {margin, 26}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {0, 0, 0}, 1, cv::LINE_AA);
  const std::array<cv::Scalar, 3> colours{cv::Scalar(200, 80, 40), cv::Scalar(60, 160, 60), cv::Scalar(60, 60, 210)};
  const double dt = world.physics.control_dt, t_end = static_cast<double>(states.size() - 1) * dt;
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const int y0 = top + static_cast<int>(p) * panel_h, y1 = y0 + panel_h - 30;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const auto& s : states)
      for (auto c : panels[p].columns) lo = std::min(lo, s[c]), hi = std::max(hi, s[c]);
    if (hi - lo < 1e-9) hi = lo + 1.0;
    const double pad = 0.05 * (hi - lo);
    lo -= pad, hi += pad;
    cv::rectangle(img, {margin, y0}, {width - 20, y1}, {180, 180, 180});
    cv::putText(img, panels[p].name, {margin + 6, y0 + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
    char tick[32];
    std::snprintf(tick, sizeof tick, "%.2f", hi);
    cv::putText(img, tick, {4, y0 + 12}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {90, 90, 90}, 1, cv::LINE_AA);
    std::snprintf(tick, sizeof tick, "%.2f", lo);
    cv::putText(img, tick, {4, y1}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {90, 90, 90}, 1, cv::LINE_AA);
    for (std::size_t k = 0; k < panels[p].columns.size(); ++k) {
      std::vector<cv::Point> pts;
      for (std::size_t t = 0; t < states.size(); ++t) {
        const double x = margin + (width - 20 - margin) * (t * dt) / std::max(t_end, dt);
        const double y = y1 - (y1 - y0) * (states[t][panels[p].columns[k]] - lo) / (hi - lo);
        pts.emplace_back(static_cast<int>(x), static_cast<int>(y));
      }
      cv::polylines(img, pts, false, colours[k], 2, cv::LINE_AA);
      cv::putText(img, panels[p].labels[k], {width - 150, y0 + 16 + 16 * static_cast<int>(k)}, cv::FONT_HERSHEY_SIMPLEX,
                  0.45, colours[k], 1, cv::LINE_AA);
    }
  }
  char axis[64];
  std::snprintf(axis, sizeof axis, "time (s), 0 to %.2f", t_end);
  cv::putText(img, axis, {width / 2 - 80, img.rows - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
  Image out_img{img.cols, img.rows, std::vector<std::uint8_t>(img.data, img.data + img.total() * img.elemSize())};
  write_png(out_img, out);
}

int run_render(const RenderOptions& opt) {
  if (opt.model.empty() == opt.episode.empty()) throw InputError("render: give exactly one of --model or --episode");
  if (opt.out.empty() && opt.plot.empty()) throw InputError("render: give --out, --plot or both");
  const WorldConfig world = opt.world.load();
  std::string title;
  const auto states = trajectory(opt, world, title);
  if (!opt.out.empty()) write_frames(states, world, title, opt.out);
  if (!opt.plot.empty()) write_plot(states, world, title, opt.plot);
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
