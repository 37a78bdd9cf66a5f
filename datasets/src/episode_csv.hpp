#pragma once
// The episode CSV's writer and its reader that also tells the layout version: what the
// demonstration folder's code (demo_set.cpp) needs beyond demo_set.hpp.
#include <filesystem>
#include <string>
#include <string_view>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/datasets/episode.hpp>

namespace dicestack::episode_csv {

/// The shortest text that reads back as exactly `v`.
std::string number_text(double v);

/// Which existing files a writer may replace: those whose first line is a CSV header of ours.
Ownership ownership();

/// Writes `e` as an episode CSV of the current layout at `path`, whole or not at all.
void write(const Episode& e, const std::filesystem::path& path, AtomicFile::Leftovers leftovers);

/// parse_episode_csv, also setting `version` to the file's layout version (by its header).
Episode parse(std::string_view text, const std::string& where, std::string name, int& version);

}  // namespace dicestack::episode_csv
