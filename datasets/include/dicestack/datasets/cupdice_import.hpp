#pragma once
// Importer for the 68 human recordings of the paper's original implementation (leonidk/cupdice,
// MIT): both layouts, converted into dicestack's units and conventions. The conversion is
// documented once, in docs/datasets.md ("Importing the original recordings").
#include <filesystem>

#include <dicestack/datasets/demo_set.hpp>

namespace dicestack {

/// The original's two file layouts.
enum class CupdiceLayout {
  final27,   ///< 27 columns: pre-step state, cup velocity after the action, the action (dv)
  legacy24,  ///< 24 columns: post-step state and the absolute cup velocity commanded
};

/// Converts one recording; the layout is told by its column count. Throws InputError with
/// "path:line:" for a malformed file (wrong column count, non-number, non-finite value, or a
/// first row that is not the original's start pose).
Episode import_cupdice_file(const std::filesystem::path& file, const WorldConfig& world);

/// Converts every *.csv under `src` (recursively; in natural path order, so final/imitate_2
/// precedes final/imitate_10) into one DemoSet with outcomes judged in `world`.
/// Throws InputError if `src` holds no recording.
DemoSet import_cupdice(const std::filesystem::path& src, const WorldConfig& world);

}  // namespace dicestack
