#include "cli.hpp"

#include <exception>
#include <iostream>

#include <dicestack/core/error.hpp>
#include <dicestack/regressors/registry.hpp>
#include <dicestack/version.hpp>

namespace dicestack::cli {

int run(int argc, char** argv) {
  CLI::App app{"dicestack: imitation learning for dynamic dice stacking", "dicestack"};
  app.set_version_flag("--version", "dicestack " DICESTACK_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // --plugin may follow any subcommand
  app.add_option("--plugin", "Load a regressor plugin (shared library); repeatable, on any subcommand")
      ->each([](const std::string& lib) { RegressorRegistry::global().load_plugin(lib); });
  add_bench_command(app);
  add_config_command(app);
  add_dataset_commands(app);
  add_evaluate_command(app);
  add_leaderboard_command(app);
  add_learners_command(app);
  add_optimise_command(app);
  add_reinforce_command(app);
  add_rrt_command(app);
  add_play_command(app);
  add_train_command(app);
  add_record_command(app);
  add_regressors_command(app);
  add_render_command(app);
  add_rollout_command(app);
  try {
    RegressorRegistry::global().load_plugins_from_environment();
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const Error& e) {
    std::cerr << "dicestack: error: " << e.what() << '\n';
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "dicestack: internal error: " << e.what() << '\n';
    return 2;
  }
  return 0;
}

}  // namespace dicestack::cli
