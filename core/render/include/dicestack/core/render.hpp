#pragma once
// Drawing a state to an image a person can read: walls, cup, dice (numbered by their pips),
// time and the judge's outcome; and a trajectory's plot over time. OpenCV stays behind this
// header (video.hpp writes whole trajectories to video, GIF or PNG files).
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <dicestack/core/judge.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// An 8-bit BGR image, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> bgr;  ///< width * height * 3 bytes
};

struct RenderOptions {
  double pixels_per_metre = 100.0;  ///< 100 reproduces the original 900 x 700 window
  bool show_hud = true;             ///< time, step and outcome text
};

/// The heads-up text drawn over a frame.
struct Hud {
  int step = 0;
  Outcome outcome;
  std::string title;  ///< e.g. the policy's name; empty for none
};

/// Renders `state` of a world built from `config`.
Image render_state(const State& state, const WorldConfig& config, const Hud& hud, const RenderOptions& options = {});

/// Same, into `image`, reusing its memory (no allocation once sized): for per-frame drawing.
void render_state_into(Image& image, const State& state, const WorldConfig& config, const Hud& hud,
                       const RenderOptions& options = {});

/// The paper's Fig. 2 for `states` (one per control step): stacked panels of the cup's x, the
/// dice's x and y, the cup's angle and its velocities over time, under `title`. 1000 px wide.
/// Requires at least one state.
Image render_plot(const std::vector<State>& states, const WorldConfig& config, const std::string& title);

/// Writes a PNG atomically. Throws InputError if it cannot be written.
void write_png(const Image& image, const std::filesystem::path& path);

}  // namespace dicestack
