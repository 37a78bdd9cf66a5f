#pragma once
// Drawing a trajectory to a file: `dicestack render` and `dicestack evaluate --video-dir` call it.
// OpenCV (video) and giflib (GIF) stay behind this header.
#include <filesystem>
#include <string>
#include <vector>

#include <dicestack/core/render.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// How frames are drawn: their scale, and one frame per `every` states (a GIF or video then
/// shows each frame for `every` control steps, so it still plays in real time).
struct FrameOptions {
  RenderOptions render;
  int every = 1;
};

/// Draws `states` (one frame each, with the judge's running outcome and `title`) to `out`:
/// FILE.mp4 or FILE.avi (OpenCV), FILE.gif (giflib), FILE.png (the last frame) or, without an
/// extension, a folder of frame_<t>.png. Throws InputError for an unknown kind or a writer that
/// cannot open.
void write_frames(const std::vector<State>& states, const WorldConfig& world, const std::string& title,
                  const std::filesystem::path& out, const FrameOptions& options = {});

}  // namespace dicestack
