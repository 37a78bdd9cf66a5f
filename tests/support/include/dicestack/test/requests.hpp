#pragma once
// An EvalRequest, a RecordRequest or a small LearnContext in one line, for the learners' tests
// (include only where dicestack::learners is linked).
#include <cstdint>
#include <vector>

#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/record.hpp>

namespace dicestack::test {

inline EvalRequest eval_request(int episodes, std::uint64_t seed, int threads, std::vector<Episode>* rollouts = nullptr,
                                InitialPush push = InitialPush::none) {
  EvalRequest r;
  r.episodes = episodes;
  r.seed = seed;
  r.threads = threads;
  r.rollouts = rollouts;
  r.push = push;
  return r;
}

inline RecordRequest record_request(int episodes, std::uint64_t seed, int threads, Action noise = {0.0, 0.0, 0.0}) {
  RecordRequest r;
  r.episodes = episodes;
  r.seed = seed;
  r.threads = threads;
  r.noise = noise;
  return r;
}

/// A context for quick learner runs: 60-step episodes, knn, seed 11, on `threads` threads.
inline LearnContext small_context(int threads) {
  LearnContext c;
  c.world.episode.max_steps = 60;
  c.regressor = "knn";
  c.seed = 11;
  c.threads = threads;
  return c;
}

}  // namespace dicestack::test
