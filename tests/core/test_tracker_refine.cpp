// The tracker's refined paths: a leading path moved by smooth offsets that CMA-ES chooses, the
// restarts over the leading paths, and the progress of the preparation.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include <dicestack/core/cluster.hpp>
#include <dicestack/core/tracker.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/paths.hpp>

namespace dicestack {
namespace {

namespace si = state_index;
using test::scripted_path;

// The scripted expert's episodes from random starts 1, 2 and 3, as recorded cup paths.
std::vector<CupPath> three_scripted_paths(const WorldConfig& w) { return {scripted_path(1, w), scripted_path(2, w), scripted_path(3, w)}; }

// A refinement small enough for a unit test: 2 generations of 3 starts, 2 bumps per axis.
void small_refinement(TrackerConfig& c) {
  c.refine = 2;
  c.refine_probes = 3;
  c.refine_knots = 2;
}

TEST(TrackerRecordings, RefineAddsTheLeadersPathMovedBySmoothOffsetsAndLeadsOnlyWhenItBeatsItsOriginal) {
  const WorldConfig w = test::short_world(200);
  const std::vector<CupPath> paths = three_scripted_paths(w);
  TrackerConfig c;
  c.probes = 4;
  const Recordings plain(paths, w, c, 7, 1);
  small_refinement(c);
  const Recordings r(paths, w, c, 7, 1);
  ASSERT_EQ(r.paths().size(), 4u);
  const CupPath& leader = paths[plain.order()[0]];
  const CupPath& refined = r.paths()[3];
  EXPECT_EQ(refined.name, leader.name + " (refined)");
  EXPECT_EQ(r.probe_trials()[3], 2 * 4 * 3) << "its validation: 4 x refine_probes fresh starts, clean and noisy";
  EXPECT_EQ(std::count(r.order().begin(), r.order().end(), 3u), 1);
  EXPECT_TRUE(r.order().front() == 3u || r.order().back() == 3u);
  if (r.order().front() != 3u) {
    EXPECT_EQ(std::vector<std::size_t>(r.order().begin(), r.order().end() - 1), plain.order());
  }
  // Its actions are folded into its velocities; the dice stay as recorded.
  for (std::size_t t = 0; t < refined.states.size(); ++t) {
    EXPECT_EQ(refined.actions[t], Action{});
    EXPECT_EQ(refined.states[t][si::die(1)], leader.states[t][si::die(1)]);
  }
  // The same on any number of threads.
  const Recordings two(paths, w, c, 7, 2);
  EXPECT_EQ(two.order(), r.order());
  EXPECT_EQ(two.probe_successes(), r.probe_successes());
  EXPECT_EQ(two.paths()[3].states, refined.states);
  // With no room to move, the refined path is the leader as followed.
  c.refine_range = {0.0, 0.0, 0.0, 0.0};
  const Recordings still(paths, w, c, 7, 1);
  EXPECT_EQ(still.order().back(), 3u) << "a tie with the leader as followed does not lead";
  for (std::size_t t = 0; t < leader.states.size(); ++t) {
    EXPECT_EQ(still.paths()[3].states[t][si::kCupX], leader.states[t][si::kCupX]);
    EXPECT_DOUBLE_EQ(still.paths()[3].states[t][si::kCupVy], leader.states[t][si::kCupVy] + leader.actions[t][1]);
  }
  // With the timing axis alone, the path is played at other times: every pose lies on the path.
  c.refine_range = {0.0, 0.0, 0.0, 0.3};
  const Recordings timed(paths, w, c, 7, 1);
  const auto [lo, hi] = std::minmax_element(leader.states.begin(), leader.states.end(),
                                            [](const State& a, const State& b) { return a[si::kCupY] < b[si::kCupY]; });
  bool moved = false;
  for (std::size_t t = 0; t < leader.states.size(); ++t) {
    const double y = timed.paths()[3].states[t][si::kCupY];
    EXPECT_GE(y, (*lo)[si::kCupY]);
    EXPECT_LE(y, (*hi)[si::kCupY]);
    moved = moved || y != leader.states[t][si::kCupY];
  }
  EXPECT_TRUE(moved);
  c.refine_probes = 0;
  EXPECT_NE(test::error_of([&] { Recordings(paths, w, c, 7); }).find("\"refine_probes\""), std::string::npos);
}

TEST(TrackerRecordings, RefineRestartsRefineTheLeadingPathsInTurnUntilOneIsEnoughAndTheBestByTheSameValidationLeads) {
  const WorldConfig w = test::short_world(200);
  const std::vector<CupPath> paths = three_scripted_paths(w);
  TrackerConfig c;
  c.probes = 4;
  const Recordings plain(paths, w, c, 7, 1);
  small_refinement(c);
  const Recordings one(paths, w, c, 7, 1);
  c.refine_restarts = 4;  // more than the paths: the fourth refines the leader again, from another seed
  const Recordings r(paths, w, c, 7, 1);
  ASSERT_EQ(r.paths().size(), 7u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(r.paths()[3 + i].name,
              paths[plain.order()[i % 3]].name + (i == 0 ? " (refined)" : " (refined, restart " + std::to_string(i) + ")"));
    EXPECT_EQ(r.probe_trials()[3 + i], 2 * 4 * 3);
  }
  EXPECT_EQ(r.paths()[3].states, one.paths()[3].states) << "the first restart is the single refinement";
  EXPECT_NE(r.paths()[6].states, r.paths()[3].states) << "the same path from another seed";
  // The best refined path (the first of equals) leads if it beats the leader as followed; every
  // other refined path follows the order as it was.
  const auto& s = r.probe_successes();
  const auto best = static_cast<std::size_t>(std::max_element(s.begin() + 3, s.end()) - s.begin());
  std::vector<std::size_t> rest(r.order().begin(), r.order().end());
  if (rest.front() == best) rest.erase(rest.begin());
  else EXPECT_EQ(std::count(rest.begin(), rest.end(), best), 1);
  EXPECT_EQ(std::vector<std::size_t>(rest.begin(), rest.begin() + 3), plain.order());
  std::vector<std::size_t> others{3, 4, 5, 6};  // the refined paths behind the order, in restart order
  if (r.order().front() == best) std::erase(others, best);
  EXPECT_EQ(std::vector<std::size_t>(rest.begin() + 3, rest.end()), others);
  for (std::size_t i = 3; i < 7; ++i) EXPECT_LT(s[i], c.refine_enough * 24) << "none was enough to stop the restarts";
  const Recordings two(paths, w, c, 7, 2);
  EXPECT_EQ(two.order(), r.order());
  EXPECT_EQ(two.probe_successes(), r.probe_successes());
  // A refined path that succeeds in refine_enough of its trials ends the restarts.
  c.refine_enough = 0.0;
  const Recordings enough(paths, w, c, 7, 1);
  ASSERT_EQ(enough.paths().size(), 4u);
  EXPECT_EQ(enough.paths()[3].states, one.paths()[3].states);
  c.refine_enough = 1.5;
  EXPECT_NE(test::error_of([&] { Recordings(paths, w, c, 7); }).find("\"refine_enough\""), std::string::npos);
  c.refine_enough = 0.8;
  c.refine_restarts = 0;
  EXPECT_NE(test::error_of([&] { Recordings(paths, w, c, 7); }).find("\"refine_restarts\""), std::string::npos);
}

TEST(TrackerRecordings, ItsPreparationReportsTheRankingAndEachRefinementsGenerations) {
  const WorldConfig w = test::short_world(200);
  const std::vector<CupPath> paths = three_scripted_paths(w);
  TrackerConfig c;
  c.probes = 4;
  small_refinement(c);
  c.refine_restarts = 2;  // none of them is enough to stop the restarts (the test above)
  std::vector<std::string> seen;
  const Recordings r(paths, w, c, 7, 1, local_cluster(), [&](const std::string& stage, int done, int total) {
    seen.push_back(stage + " " + std::to_string(done) + "/" + std::to_string(total));
  });
  const std::vector<std::string> expected{"ranking the paths 0/1",    "ranking the paths 1/1",    "refining path 1 of 2 1/2",
                                          "refining path 1 of 2 2/2", "refining path 2 of 2 1/2", "refining path 2 of 2 2/2"};
  EXPECT_EQ(seen, expected);
  const Recordings unwatched(paths, w, c, 7, 1);
  EXPECT_EQ(r.order(), unwatched.order());
  EXPECT_EQ(r.probe_successes(), unwatched.probe_successes());
}

}  // namespace
}  // namespace dicestack
