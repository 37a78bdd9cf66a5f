#pragma once
// Drawing a trajectory to a file: `dicestack render` and `dicestack evaluate --video-dir` call it.
// OpenCV (video) and giflib (GIF) stay behind this header.
#include <filesystem>
#include <string>
#include <vector>

#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// Draws `states` (one frame each, with the judge's running outcome and `title`) to `out`:
/// FILE.mp4 or FILE.avi (OpenCV), FILE.gif (giflib), FILE.png (the last frame) or, without an
/// extension, a folder of frame_<t>.png. Throws InputError for an unknown kind or a writer that
/// cannot open.
void write_frames(const std::vector<State>& states, const WorldConfig& world, const std::string& title,
                  const std::filesystem::path& out);

}  // namespace dicestack
