#pragma once
// The reference pages generated from the registries' schemas (`dicestack learners --markdown`,
// `dicestack regressors --markdown`): what docs/reference/ holds, so they cannot drift.
#include <string>

namespace dicestack::cli {

/// Every learner, its default feature map and its options as Markdown tables; then the feature
/// maps' grammar and the listed maps.
std::string learners_reference_markdown();

/// Every registered regressor and its parameters as Markdown tables.
std::string regressors_reference_markdown();

}  // namespace dicestack::cli
