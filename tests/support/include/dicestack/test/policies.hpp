#pragma once
// A policy for the learners' tests that runs anywhere and shows what it was shown (include only
// where dicestack::learners is linked).
#include <memory>
#include <string>
#include <vector>

#include <dicestack/core/types.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/policy.hpp>

namespace dicestack::test {

/// A fixed swing that reads the state it is shown, and remembers every state it saw.
class Watcher final : public Policy {
 public:
  Action act(const History& h) override {
    seen.push_back(h.current());
    const State& s = h.current();
    return {(h.t() / 10) % 2 ? 0.4 : -0.4, 4.0 / 30.0 - s[state_index::kCupVy] * 0.5, -0.1 * s[state_index::kCupW]};
  }
  std::string name() const override { return "watcher"; }
  std::vector<State> seen;
};

/// Makes a Watcher.
inline const PolicyFactory watcher = [] { return std::make_unique<Watcher>(); };

}  // namespace dicestack::test
