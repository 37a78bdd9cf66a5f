#include "options.hpp"

#include <iostream>

namespace dicestack::cli {

void WorldOption::add_to(CLI::App& app) {
  app.add_option("--world", path, "World config JSON (defaults: the paper's world; see `dicestack config`)")
      ->check(CLI::ExistingFile);
}

WorldConfig WorldOption::load() const { return path.empty() ? WorldConfig{} : load_world_config(path); }

void print_line(const std::string& text) { std::cout << text << '\n' << std::flush; }

}  // namespace dicestack::cli
