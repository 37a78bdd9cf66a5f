#pragma once
// Demonstrations the learners' tests learn from, each made once per process (include only where
// dicestack::learners is linked).
#include <vector>

#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/data_paths.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/episode.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack::test {

/// Scripted-expert episodes of 60 steps: demonstrations the world replays bit for bit.
inline const std::vector<Episode>& demos() {
  static const std::vector<Episode> d = record_expert("scripted", {}, short_world(), record_request(3, 5, 1));
  return d;
}

/// Six of the paper's human recordings (made in Chipmunk, imported once into the cache).
inline const std::vector<Episode>& human_six() {
  static const std::vector<Episode> six = [] {
    auto all = read_demo_set(human_demo_set(WorldConfig{})).episodes;
    all.resize(6);
    return all;
  }();
  return six;
}

}  // namespace dicestack::test
