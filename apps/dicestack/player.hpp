#pragma once
// The interactive game: the paper's control scheme in an SDL2 window at 30 frames per second,
// recording every episode in dicestack's demonstration format.
#include <cstdint>
#include <filesystem>
#include <string>

#include <dicestack/core/world_config.hpp>

namespace dicestack::cli {

struct PlayOptions {
  WorldConfig world;
  std::filesystem::path record;          ///< append every episode here (empty: do not record)
  std::filesystem::path screenshot_dir;  ///< where 'p' saves PNGs (empty: current folder)
  std::uint64_t seed = 0;                ///< first episode's start; later ones use seed + k
  bool paper_start = false;              ///< start from the paper's state instead of a random one
  double scale = 1.0;                    ///< window size relative to the original 900 x 700
  double max_seconds = 0.0;              ///< quit after this long (0: play until closed)
};

/// What a session did, reported when the window closes.
struct PlayReport {
  int episodes_recorded = 0;
  long frames = 0;
  double seconds = 0.0;
  double render_ms = 0.0;   ///< mean drawing time per frame
  double physics_ms = 0.0;  ///< mean simulation time per frame
};

/// Runs the game until the window is closed, Escape is pressed or max_seconds pass.
/// Throws Error if no window can be opened (e.g. no display).
PlayReport play(const PlayOptions& options);

}  // namespace dicestack::cli
