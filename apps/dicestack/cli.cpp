#include "cli.hpp"

#include <exception>
#include <iostream>
#include <set>
#include <string>

#include <dicestack/core/error.hpp>
#include <dicestack/core/interrupt.hpp>
#include <dicestack/regressors/registry.hpp>
#include <dicestack/version.hpp>

namespace dicestack::cli {

namespace {

// Thrown on a rank other than the root when the subcommand runs on the root alone.
struct RootOnly {};

}  // namespace

int run(int argc, char** argv, Cluster& cluster, const FailFn& fail_fn) {
  // Every message is shown with any overlong value a user gave cut short (readable_message).
  const FailFn fail = [&fail_fn](const std::string& message, int code) {
    if (fail_fn) return fail_fn(readable_message(message), code);
    std::cerr << readable_message(message) << '\n';
    return code;
  };
  CLI::App app{"dicestack: imitation learning for dynamic dice stacking", "dicestack"};
  app.failure_message([](const CLI::App* parsed, const CLI::Error& e) {
    return readable_message(CLI::FailureMessage::simple(parsed, e));
  });
  app.set_version_flag("--version", "dicestack " DICESTACK_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // --plugin may follow any subcommand
  app.add_option("--plugin", "Load a regressor plugin (shared library); repeatable, on any subcommand")
      ->each([](const std::string& lib) { RegressorRegistry::global().load_plugin(lib); });
  add_bench_command(app);
  add_config_command(app);
  add_dataset_commands(app);
  add_evaluate_command(app, cluster);
  add_leaderboard_command(app, cluster);
  add_learners_command(app);
  add_optimise_command(app, cluster);
  add_reinforce_command(app, cluster);
  add_rrt_command(app, cluster);
  add_play_command(app);
  add_train_command(app, cluster);
  add_record_command(app, cluster);
  add_regressors_command(app);
  add_render_command(app);
  add_rollout_command(app);
  add_robustness_command(app, cluster);
  add_reference_command(app);
  // The long runs, whose work is dealt over threads and ranks. Ctrl-C stops them as an error
  // would, at the next episode (interrupt.hpp); the other subcommands keep the default (play
  // waits for keys, and must end at once). With several ranks, the other subcommands run on the
  // root alone.
  static const std::set<std::string> distributed{"evaluate", "record",    "train", "leaderboard",
                                                 "optimise", "reinforce", "rrt",   "robustness"};
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
    if (distributed.contains(sub->get_name()))
      sub->preparse_callback([](std::size_t) { install_interrupt_handler(); });
    else if (cluster.size() > 1)
      sub->preparse_callback([&cluster](std::size_t) {
        if (!cluster.is_root()) throw RootOnly{};
      });
  }
  try {
    RegressorRegistry::global().load_plugins_from_environment();
    app.parse(argc, argv);
  } catch (const RootOnly&) {
    return 0;  // the root runs this subcommand
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const Interrupted&) {
    return fail("dicestack: interrupted", 130);
  } catch (const Error& e) {
    return fail(std::string("dicestack: error: ") + e.what(), 1);
  } catch (const std::exception& e) {
    return fail(std::string("dicestack: internal error: ") + e.what(), 2);
  }
  return 0;
}

}  // namespace dicestack::cli
