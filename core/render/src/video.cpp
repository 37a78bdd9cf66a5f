// Frames of a trajectory to a video, a GIF, a PNG or a folder of PNGs: `dicestack render` and
// `dicestack evaluate --video-dir` draw with it.
#include <dicestack/core/video.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <dlfcn.h>

#include <memory>

#include <dicestack/core/error.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/render.hpp>
#include <dicestack/core/world.hpp>

#include "gif_writer.hpp"
#include "video_sink.hpp"

namespace dicestack {

namespace fs = std::filesystem;

namespace {

using OpenVideo = VideoSink* (*)(const char*, int, double, int, int);

// The video module's entry, loaded once from beside this library (the build tree and an
// install keep them in one folder). Throws InputError naming `out` when it cannot be loaded.
OpenVideo video_module(const fs::path& out) {
  static const std::pair<OpenVideo, std::string> loaded = [] {
    Dl_info self{};
    const fs::path here = dladdr(reinterpret_cast<void*>(&write_frames), &self) != 0 && self.dli_fname != nullptr
                              ? fs::path(self.dli_fname).parent_path()
                              : fs::path();
    const fs::path module = here / kVideoModuleFile;
    void* handle = dlopen(module.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) return std::pair<OpenVideo, std::string>{nullptr, dlerror()};
    auto* entry = reinterpret_cast<OpenVideo>(dlsym(handle, kOpenVideoSymbol));
    if (entry == nullptr) return std::pair<OpenVideo, std::string>{nullptr, module.string() + ": no " + kOpenVideoSymbol};
    return std::pair<OpenVideo, std::string>{entry, ""};
  }();
  if (loaded.first == nullptr)
    throw InputError(out.string() + ": videos are written by " + kVideoModuleFile +
                     ", which did not load (" + loaded.second + "); write a .gif or PNG frames instead");
  return loaded.first;
}

}  // namespace

void write_frames(const std::vector<State>& states, const WorldConfig& world, const std::string& title, const fs::path& out,
                  const FrameOptions& options) {
  if (options.every < 1) throw InputError(out.string() + ": frames every " + std::to_string(options.every) + " states (at least 1)");
  const auto every = static_cast<std::size_t>(options.every);
  const RenderOptions& look = options.render;
  // Outcome per frame, as the judge saw it.
  std::vector<Outcome> outcomes;
  Outcome o;
  World probe(world);
  for (std::size_t t = 0; t < states.size(); ++t) {
    if (t > 0) {
      probe.set_state(states[t]);
      observe(o, states[t], probe.touching_walls(), world);
    }
    outcomes.push_back(o);
  }
  const auto ext = out.extension().string();
  Image img;
  if (ext.empty()) {  // a folder of PNGs
    fs::create_directories(out);
    for (std::size_t t = 0; t < states.size(); t += every) {
      render_state_into(img, states[t], world, {static_cast<int>(t), outcomes[t], title}, look);
      char name[32];
      std::snprintf(name, sizeof name, "frame_%04zu.png", t);
      write_png(img, out / name);
    }
    return;
  }
  if (ext != ".mp4" && ext != ".avi" && ext != ".gif" && ext != ".png")
    throw InputError(out.string() + ": unknown output kind; use .mp4, .avi, .gif, .png (last frame) or a folder");
  if (ext == ".png") {
    render_state_into(img, states.back(), world, {static_cast<int>(states.size() - 1), outcomes.back(), title}, look);
    write_png(img, out);
    return;
  }
  render_state_into(img, states.front(), world, {0, outcomes.front(), title}, look);
  const fs::path tmp = out.parent_path() / (".tmp-" + out.filename().string());
  if (ext == ".gif") {
    GifWriter gif(tmp, img.width, img.height);
    const double cs = 100.0 * world.physics.control_dt;  // GIF delays are whole centiseconds: carry the rest
    for (std::size_t t = 0; t < states.size(); t += every) {
      render_state_into(img, states[t], world, {static_cast<int>(t), outcomes[t], title}, look);
      const std::size_t next = std::min(t + every, states.size());
      gif.add(img, static_cast<int>(std::lround(next * cs) - std::lround(t * cs)));
    }
    gif.close();
    fs::rename(tmp, out);
    return;
  }
  const std::unique_ptr<VideoSink> video(video_module(out)(tmp.c_str(), ext == ".mp4" ? 1 : 0,
                                                          1.0 / (world.physics.control_dt * options.every), img.width,
                                                          img.height));
  if (!video) throw InputError(out.string() + ": OpenCV cannot write this video format here");
  for (std::size_t t = 0; t < states.size(); t += every) {
    render_state_into(img, states[t], world, {static_cast<int>(t), outcomes[t], title}, look);
    video->add(img.bgr.data());
  }
  video->close();
  fs::rename(tmp, out);
}

}  // namespace dicestack
