// `dicestack reference PAGE`: print a reference page of docs/reference/, generated from the code.
#include <iostream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cli.hpp"
#include "reference_md.hpp"

namespace dicestack::cli {

void add_reference_command(CLI::App& app) {
  auto page = std::make_shared<std::string>();
  const std::map<std::string, std::string> pages{{"cli", "every subcommand and its options"},
                                                 {"learners", "the learners, their options and the feature maps"},
                                                 {"perturbations", "the perturbation levels and file keys"},
                                                 {"regressors", "the built-in regressors and their parameters"},
                                                 {"world-config", "every field of the world config file"}};
  std::string what = "The page: ";
  std::vector<std::string> names;
  for (const auto& [name, text] : pages) {
    what += (names.empty() ? "" : "; ") + name + " (" + text + ")";
    names.push_back(name);
  }
  CLI::App* cmd = app.add_subcommand("reference", "Print a reference page of docs/reference/, generated from the code");
  cmd->add_option("page", *page, what)->required()->check(CLI::IsMember(names));
  // The root app is complete by the time a callback runs, so the cli page sees every subcommand.
  cmd->callback([page, &app] {
    if (*page == "cli") std::cout << cli_reference_markdown(app);
    else if (*page == "learners") std::cout << learners_reference_markdown();
    else if (*page == "perturbations") std::cout << perturbations_reference_markdown();
    else if (*page == "regressors") std::cout << regressors_reference_markdown();
    else std::cout << world_config_reference_markdown();
  });
}

}  // namespace dicestack::cli
