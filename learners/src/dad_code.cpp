#include "dad_code.hpp"

#include <algorithm>
#include <iterator>

#include <dicestack/core/error.hpp>

namespace dicestack {

namespace {
constexpr const char* kCodePartNames[] = {"start", "label", "cost", "schedule", "search", "duplicates", "units"};
}  // namespace

CodeParts code_parts(const std::string& text) {
  CodeParts p;
  if (text == "false") return p;
  if (text == "true") return {true, true, true, true, true, true, true};
  bool* fields[] = {&p.start, &p.label, &p.cost, &p.schedule, &p.search, &p.duplicates, &p.units};
  for (std::size_t from = 0; from <= text.size();) {
    const std::size_t plus = std::min(text.find('+', from), text.size());
    const std::string part = text.substr(from, plus - from);
    const auto* it = std::find(std::begin(kCodePartNames), std::end(kCodePartNames), part);
    if (it == std::end(kCodePartNames))
      throw ConfigError("dad: parameter \"faithful\": unknown part \"" + part.substr(0, 40) + (part.size() > 40 ? "...\"" : "\"") +
                        "; expected true, false, or parts joined by '+': start, label, cost, schedule, search, duplicates, units");
    *fields[it - std::begin(kCodePartNames)] = true;
    from = plus + 1;
  }
  return p;
}

Action scaled(Action a, const Action& by) {
  for (std::size_t k = 0; k < kActionDim; ++k) a[k] *= by[k];
  return a;
}

}  // namespace dicestack
