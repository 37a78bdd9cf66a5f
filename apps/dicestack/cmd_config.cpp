// `dicestack config`: print or write the default world config, or check a config file.
#include <iostream>

#include <dicestack/core/world_config.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

struct ConfigOptions {
  std::filesystem::path out;
  std::filesystem::path check;
};

int run_config(const ConfigOptions& opt) {
  if (!opt.check.empty()) {
    load_world_config(opt.check);
    print_line(opt.check.string() + ": valid world config");
    return 0;
  }
  const WorldConfig defaults;
  if (opt.out.empty()) {
    std::cout << to_json(defaults);
  } else {
    save_world_config(defaults, opt.out);
    print_line("wrote " + opt.out.string());
  }
  return 0;
}

}  // namespace

void add_config_command(CLI::App& app) {
  auto opt = std::make_shared<ConfigOptions>();
  CLI::App* cmd = app.add_subcommand("config", "Print or write the default world config, or check a config file");
  cmd->add_option("--out", opt->out, "Write the defaults to this JSON file instead of printing them");
  cmd->add_option("--check", opt->check, "Validate this world config JSON and report the first bad field")
      ->check(CLI::ExistingFile);
  cmd->callback([opt] { run_config(*opt); });
}

}  // namespace dicestack::cli
