#pragma once
// Options shared by several subcommands.
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include <dicestack/core/world_config.hpp>

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

}  // namespace dicestack::cli
