#include "options.hpp"

#include <cstdio>
#include <iostream>

#include <unistd.h>

#include <dicestack/datasets/builtin.hpp>
#include <dicestack/learners/record.hpp>

namespace dicestack::cli {

void WorldOption::add_to(CLI::App& app) {
  app.add_option("--world", path, "World config JSON (defaults: the paper's world; see `dicestack config`)")
      ->check(CLI::ExistingFile);
}

WorldConfig WorldOption::load() const { return path.empty() ? WorldConfig{} : load_world_config(path); }

void print_line(const std::string& text) { std::cout << text << '\n' << std::flush; }

void print_progress(const std::string& text) {
  static const bool tty = isatty(fileno(stderr));
  if (tty) std::cerr << "\r\033[K" << text << std::flush;
  else std::cerr << text << '\n';
}

void DemosOption::add_to(CLI::App& app) {
  app.add_option("--demos", path,
                 "Demonstration folder, or `builtin` (default: 80 expert successes) or `human` (the paper's 68 "
                 "recordings, converted)");
}

std::filesystem::path DemosOption::resolve(const WorldConfig& world) const {
  if (path.empty() || (path == "builtin" && !std::filesystem::exists(path))) return builtin_demo_set(world);
  if (path == "human" && !std::filesystem::exists(path)) return human_demo_set(world);
  return path;
}

}  // namespace dicestack::cli
