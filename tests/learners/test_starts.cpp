// The start streams: training and evaluation starts share no seed and no start, so a model is
// never evaluated from a start it was trained on.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <set>
#include <vector>

#include <dicestack/core/initial_state.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/policy.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

TEST(Starts, TrainingAndEvaluationStreamsShareNoStart) {
  // Every seed a user is likely to type, on both sides: no start seed (hence no start) in common.
  std::set<std::uint64_t> evaluation;
  for (std::uint64_t s = 0; s < 20; ++s)
    for (std::uint64_t i = 0; i < 500; ++i) evaluation.insert(evaluation_start_seed(s, i));
  for (std::uint64_t s = 0; s < 20; ++s)
    for (std::uint64_t i = 0; i < 500; ++i) ASSERT_FALSE(evaluation.contains(training_start_seed(s, i))) << s << " " << i;
  // And the starts themselves: record --seed 0 against evaluate --seed 0.
  const WorldConfig w = test::short_world();
  const auto recorded = record_expert("scripted", {}, w, test::record_request(5, 0, 1));
  std::vector<Episode> evaluated;
  evaluate([] { return std::make_unique<PlaybackPolicy>(Episode{}); }, w, test::eval_request(5, 0, 1, &evaluated));
  for (const auto& r : recorded)
    for (const auto& e : evaluated) EXPECT_NE(r.states.front(), e.states.front());
}

}  // namespace
}  // namespace dicestack
