#pragma once
// Small hand-made episodes, and episodes compared field by field (GoogleTest expectations): what
// a round trip through any format or transport must give back.
#include <gtest/gtest.h>

#include <cstddef>
#include <string>
#include <vector>

#include <dicestack/datasets/episode.hpp>

namespace dicestack::test {

/// An expert episode `name` of `n` steps: at step t every state value is offset + t and the
/// action is (offset, t, -1).
inline Episode tiny(const std::string& name, std::size_t n, double offset) {
  Episode e;
  e.name = name;
  for (std::size_t t = 0; t < n; ++t) {
    State s{};
    s.fill(offset + static_cast<double>(t));
    e.states.push_back(s);
    e.actions.push_back({offset, static_cast<double>(t), -1.0});
    e.sources.push_back(StepSource::expert);
  }
  return e;
}

/// `count` tiny episodes e0, e1, ...: episode i has 2 + i % 3 steps and offset 10 i.
inline std::vector<Episode> episodes(std::size_t count) {
  std::vector<Episode> out;
  for (std::size_t i = 0; i < count; ++i) {
    std::string name(1, 'e');
    name += std::to_string(i);  // (GCC 12 warns falsely on "e" + to_string)
    out.push_back(tiny(name, 2 + i % 3, 10.0 * static_cast<double>(i)));
  }
  return out;
}

inline void expect_same_episode(const Episode& x, const Episode& y) {
  SCOPED_TRACE(x.name);
  EXPECT_EQ(x.name, y.name);
  EXPECT_EQ(x.seed, y.seed);
  EXPECT_EQ(x.origin, y.origin);
  EXPECT_EQ(x.states, y.states);
  EXPECT_EQ(x.actions, y.actions);
  EXPECT_EQ(x.sources, y.sources);
  EXPECT_EQ(x.links, y.links);
  EXPECT_EQ(x.joint_torques, y.joint_torques);
  EXPECT_EQ(x.final_links, y.final_links);
  EXPECT_EQ(x.final_state, y.final_state);
  EXPECT_EQ(x.rewards, y.rewards);
  EXPECT_EQ(x.terminated, y.terminated);
  EXPECT_EQ(x.truncated, y.truncated);
  EXPECT_EQ(x.outcome.steps, y.outcome.steps);
  EXPECT_EQ(x.outcome.dice_in_cup, y.outcome.dice_in_cup);
  EXPECT_EQ(x.outcome.stacked, y.outcome.stacked);
  EXPECT_EQ(x.outcome.wall_contact, y.outcome.wall_contact);
}

}  // namespace dicestack::test
