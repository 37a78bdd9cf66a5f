// Frames of a trajectory to a video, a GIF, a PNG or a folder of PNGs: `dicestack render` and
// `dicestack evaluate --video-dir` draw with it.
#include <dicestack/core/video.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/videoio.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/render.hpp>
#include <dicestack/core/world.hpp>

#include "gif_writer.hpp"

namespace dicestack {

namespace fs = std::filesystem;

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
  const int fourcc = ext == ".mp4" ? cv::VideoWriter::fourcc('m', 'p', '4', 'v') : cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
  cv::VideoWriter video(tmp.string(), cv::CAP_FFMPEG, fourcc, 1.0 / (world.physics.control_dt * options.every),
                        cv::Size(img.width, img.height));
  if (!video.isOpened()) throw InputError(out.string() + ": OpenCV cannot write this video format here");
  for (std::size_t t = 0; t < states.size(); t += every) {
    render_state_into(img, states[t], world, {static_cast<int>(t), outcomes[t], title}, look);
    video.write(cv::Mat(img.height, img.width, CV_8UC3, img.bgr.data()));
  }
  video.release();
  fs::rename(tmp, out);
}

}  // namespace dicestack
