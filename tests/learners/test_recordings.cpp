// Picking recordings: a seeded subset of the demonstrations for the tracker to follow, and all
// of them when asked for all.
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include <dicestack/datasets/episode.hpp>
#include <dicestack/learners/demonstrator.hpp>

#include <dicestack/test/demos.hpp>

namespace dicestack {
namespace {

using test::human_six;

TEST(Recordings, PickedSubsetsAreSeededAndAllMeansAll) {
  const auto names = [](const std::vector<Episode>& es) {
    std::vector<std::string> out;
    for (const auto& e : es) out.push_back(e.name);
    return out;
  };
  EXPECT_EQ(names(pick_recordings(human_six(), 0, 1)), names(human_six()));
  EXPECT_EQ(names(pick_recordings(human_six(), 6, 1)), names(human_six()));
  const auto three = pick_recordings(human_six(), 3, 1);
  ASSERT_EQ(three.size(), 3u);
  EXPECT_EQ(names(pick_recordings(human_six(), 3, 1)), names(three));
  std::set<std::string> distinct;
  for (const auto& n : names(three)) distinct.insert(n);
  EXPECT_EQ(distinct.size(), 3u);
  bool another = false;  // some other seed draws another subset
  for (std::uint64_t seed = 2; seed < 10 && !another; ++seed) another = names(pick_recordings(human_six(), 3, seed)) != names(three);
  EXPECT_TRUE(another);
}

}  // namespace
}  // namespace dicestack
