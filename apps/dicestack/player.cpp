#include "player.hpp"

#include <SDL2/SDL.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>

#include <dicestack/core/env.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/render.hpp>
#include <dicestack/datasets/demo_set.hpp>

namespace dicestack::cli {
namespace {

namespace si = state_index;
using Clock = std::chrono::steady_clock;

constexpr double kLinearKick = 1.0;  // m/s per frame while an arrow is held (DESIGN "human keys")
constexpr double kAngularKick = 0.5; // rad/s per frame while q or e is held
constexpr double kAimGain = 10.0;    // angular velocity per radian of aim error (mouse aim)

struct SdlSession {
  SDL_Window* window = nullptr;
  SDL_Renderer* renderer = nullptr;
  SDL_Texture* texture = nullptr;
  SdlSession(int w, int h, double scale) {
    if (SDL_Init(SDL_INIT_VIDEO) != 0)
      throw Error(std::string("play: cannot start SDL video: ") + SDL_GetError() +
                  " (is there a display? try xvfb-run for a headless machine)");
    window = SDL_CreateWindow("dicestack", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED,
                              static_cast<int>(w * scale), static_cast<int>(h * scale), SDL_WINDOW_SHOWN);
    if (!window) fail("cannot open a window");
    renderer = SDL_CreateRenderer(window, -1, 0);
    if (!renderer) fail("cannot create a renderer");
    texture = SDL_CreateTexture(renderer, SDL_PIXELFORMAT_BGR24, SDL_TEXTUREACCESS_STREAMING, w, h);
    if (!texture) fail("cannot create a texture");
  }
  ~SdlSession() {
    if (texture) SDL_DestroyTexture(texture);
    if (renderer) SDL_DestroyRenderer(renderer);
    if (window) SDL_DestroyWindow(window);
    SDL_Quit();
  }
  [[noreturn]] void fail(const char* what) { throw Error(std::string("play: ") + what + ": " + SDL_GetError()); }
  void show(const Image& img) {
    SDL_UpdateTexture(texture, nullptr, img.bgr.data(), img.width * 3);
    SDL_RenderClear(renderer);
    SDL_RenderCopy(renderer, texture, nullptr, nullptr);
    SDL_RenderPresent(renderer);
  }
};

// The paper's control scheme: held keys add to the cup's velocity every frame; a component
// whose keys are released is stopped; mouse aim turns the cup's mouth toward the pointer.
Action human_action(const State& s, const Uint8* keys, std::optional<Vec2> aim) {
  const double vx = s[si::kCupVx], vy = s[si::kCupVy], w = s[si::kCupW];
  auto axis = [](bool minus, bool plus, double v, double kick) {
    if (minus == plus) return -v;  // released (or both): stop
    return plus ? kick : -kick;
  };
  Action a{axis(keys[SDL_SCANCODE_LEFT], keys[SDL_SCANCODE_RIGHT], vx, kLinearKick),
           axis(keys[SDL_SCANCODE_DOWN], keys[SDL_SCANCODE_UP], vy, kLinearKick),
           axis(keys[SDL_SCANCODE_E], keys[SDL_SCANCODE_Q], w, kAngularKick)};
  if (aim && keys[SDL_SCANCODE_Q] == keys[SDL_SCANCODE_E]) {
    // The mouth (the cup's local +y) points at the pointer.
    double err = std::atan2(aim->y - s[si::kCupY], aim->x - s[si::kCupX]) - (s[si::kCupAngle] + std::numbers::pi / 2);
    err = std::remainder(err, 2.0 * std::numbers::pi);
    a[2] = kAimGain * err - w;
  }
  return a;
}

}  // namespace

PlayReport play(const PlayOptions& opt) {
  DiceEnv env(opt.world);
  const Image probe = render_state(paper_start_state(opt.world), opt.world, {});
  SdlSession sdl(probe.width, probe.height, opt.scale);

  PlayReport report;
  std::uint64_t episode_seed = opt.seed;
  Episode episode;
  auto start_episode = [&] {
    episode = Episode{};
    episode.seed = episode_seed;
    episode.origin = "dicestack play";
    if (opt.paper_start) env.reset_to(paper_start_state(opt.world), episode_seed);
    else env.reset(episode_seed);
    ++episode_seed;
  };
  auto finish_episode = [&] {
    if (!opt.record.empty() && episode.size() > 0) {
      episode.outcome = env.outcome();
      if (!episode.final_state) {  // saved or closed before the episode ended: a truncation
        episode.final_state = env.get_state();
        episode.truncated = true;
      }
      append_to_demo_set(opt.record, {episode}, opt.world, "recorded with dicestack play");
      ++report.episodes_recorded;
    }
  };
  start_episode();

  const double frame_s = opt.world.physics.control_dt;
  const auto t0 = Clock::now();
  auto next_frame = t0;
  bool aim = false, running = true;
  int shots = 0, celebrate = 0;
  double render_s = 0.0, physics_s = 0.0;
  Image img;
  while (running) {
    std::optional<std::string> screenshot;
    SDL_Event ev;
    while (SDL_PollEvent(&ev)) {
      if (ev.type == SDL_QUIT) running = false;
      if (ev.type != SDL_KEYDOWN || ev.key.repeat) continue;
      switch (ev.key.keysym.sym) {
        case SDLK_ESCAPE: running = false; break;
        case SDLK_m: aim = !aim; break;
        case SDLK_r: start_episode(); break;                   // discard and start over
        case SDLK_s: finish_episode(); start_episode(); break;  // save and start over
        case SDLK_p: screenshot = "dicestack_" + std::to_string(shots++) + ".png"; break;
        default: break;
      }
    }
    const Uint8* keys = SDL_GetKeyboardState(nullptr);
    std::optional<Vec2> pointer;
    if (aim) {
      int mx = 0, my = 0;
      SDL_GetMouseState(&mx, &my);
      pointer = Vec2{mx / opt.scale / 100.0, (probe.height - my / opt.scale) / 100.0};
    }
    const auto p0 = Clock::now();
    if (celebrate > 0) {
      if (--celebrate == 0) start_episode();
    } else {
      const State s = env.get_state();
      const Action a = human_action(s, keys, pointer);
      const StepResult r = env.step(a);
      episode.states.push_back(s);
      episode.actions.push_back(a);
      episode.sources.push_back(StepSource::human);
      episode.rewards.push_back(r.reward);
      if (r.terminated || r.truncated) {
        episode.final_state = r.observation;
        episode.terminated = r.terminated;
        episode.truncated = r.truncated;
        finish_episode();
        celebrate = r.terminated ? static_cast<int>(1.5 / frame_s) : 1;
      }
    }
    const auto p1 = Clock::now();
    const Outcome& o = env.outcome();
    render_state_into(img, env.get_state(), opt.world,
                      {o.steps, o, std::string("dicestack play") + (aim ? "  [mouse aim]" : "") +
                                       (opt.record.empty() ? "" : "  [recording]")});
    if (screenshot) write_png(img, (opt.screenshot_dir.empty() ? std::filesystem::path(".") : opt.screenshot_dir) / *screenshot);
    sdl.show(img);
    const auto p2 = Clock::now();
    physics_s += std::chrono::duration<double>(p1 - p0).count();
    render_s += std::chrono::duration<double>(p2 - p1).count();
    ++report.frames;

    next_frame += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(frame_s));
    const auto now = Clock::now();
    if (next_frame > now) SDL_Delay(static_cast<Uint32>(std::chrono::duration<double, std::milli>(next_frame - now).count()));
    else next_frame = now;  // fell behind: do not try to catch up in a burst
    report.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    if (opt.max_seconds > 0.0 && report.seconds >= opt.max_seconds) running = false;
  }
  finish_episode();
  report.render_ms = 1e3 * render_s / static_cast<double>(report.frames);
  report.physics_ms = 1e3 * physics_s / static_cast<double>(report.frames);
  return report;
}

}  // namespace dicestack::cli
