#pragma once
// Options shared by several subcommands.
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/demo_set.hpp>

namespace dicestack::cli {

/// `--world FILE`: a WorldConfig JSON (`dicestack config` writes the defaults).
struct WorldOption {
  std::filesystem::path path;
  void add_to(CLI::App& app);
  /// The config from the file, or the defaults when no file was given.
  WorldConfig load() const;
};

/// Prints a JSON object or a human-readable text on stdout.
void print_line(const std::string& text);

/// Prints progress on stderr (overwriting the line when stderr is a terminal).
void print_progress(const std::string& text);

/// `--demos DIR`: a demonstration folder; without it, the built-in set.
struct DemosOption {
  std::filesystem::path path;
  void add_to(CLI::App& app);
  /// The folder to read (the built-in set is prepared on first use).
  std::filesystem::path resolve(const WorldConfig& world) const;
};

}  // namespace dicestack::cli
