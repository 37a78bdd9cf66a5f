#pragma once
// The reference pages generated from the code (`dicestack reference PAGE`): what docs/reference/
// holds up to each page's version history, so they cannot drift.
#include <string>

namespace CLI {
class App;
}

namespace dicestack::cli {

/// Every subcommand of `app`, its options, their values and defaults, as Markdown tables.
std::string cli_reference_markdown(const CLI::App& app);

/// Every field of the world config file: type, default, range and meaning.
std::string world_config_reference_markdown();

/// The perturbation levels, factor by factor, and the keys of a perturbation file.
std::string perturbations_reference_markdown();

/// Every learner, its default feature map and its options as Markdown tables; then the feature
/// maps' grammar and the listed maps.
std::string learners_reference_markdown();

/// Every registered regressor and its parameters as Markdown tables.
std::string regressors_reference_markdown();

}  // namespace dicestack::cli
