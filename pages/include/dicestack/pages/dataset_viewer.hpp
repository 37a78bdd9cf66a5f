#pragma once
// The episode viewer of a demonstration set: one page for a browser, written with its media
// folder as one unit (docs/results-pages.md).
#include <filesystem>
#include <string>

#include <dicestack/datasets/demo_set.hpp>

namespace dicestack {

/// `dicestack dataset view`: an episode browser for `set` (named `name` on the page). The page
/// lists the episodes with their outcomes; the chosen one plays as an animation drawn from its
/// recorded states, in step with plots of the cup's x, y and angle, the dice's heights and the
/// three actions, a cursor following the playback. Each episode's numbers are a script in
/// <page>_files/m-<digest>/episodes/ that the page loads when it is chosen (a file:// page cannot
/// fetch), so the page stays small for any number of episodes. The page and that folder are
/// written as one unit, as write_results_page's. Replaces only a page and folder of ours.
void write_dataset_viewer(const DemoSet& set, const std::string& name, const std::filesystem::path& page);

}  // namespace dicestack
