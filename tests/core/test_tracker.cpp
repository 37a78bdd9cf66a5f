// The tracker: recorded cup paths followed by feedback on the cup, chosen by
// simulation.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <dicestack/core/error.hpp>
#include <dicestack/core/expert.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/tracker.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/paths.hpp>

namespace dicestack {
namespace {

namespace si = state_index;
using test::scripted_path;

// The first `n` scripted episodes (random starts 0, 1, ...) that end in a realistic success.
std::vector<CupPath> successful_scripted_paths(std::size_t n) {
  std::vector<CupPath> paths;
  for (std::uint64_t s = 0; paths.size() < n; ++s) {
    DiceEnv env(WorldConfig{});
    env.reset(s);
    auto expert = make_expert("scripted");
    expert->reset(s);
    const ExpertEpisode e = run_expert_episode(*expert, env, true);
    if (e.outcome.realistic_success()) paths.push_back({"p" + std::to_string(s), e.states, e.actions});
  }
  return paths;
}

double mean_dice_x(const State& s) { return (s[si::die(0)] + s[si::die(1)] + s[si::die(2)]) / 3.0; }

// Follows `follower` from `start` for the path's length; the largest |cup x - (recorded x + shift)|.
double largest_x_error(const CupPath& path, const State& start, double shift, const WorldConfig& world) {
  DiceEnv env(world);
  env.reset_to(start);
  const PathFollower follower(path, {}, start, 0, TrackerConfig{}.gain);
  double worst = 0.0;
  for (std::size_t t = 0; t + 1 < path.states.size(); ++t) {
    env.step(follower.act(env.get_state(), env.t()));
    worst = std::max(worst, std::abs(env.get_state()[si::kCupX] - (path.states[t + 1][si::kCupX] + shift)));
  }
  return worst;
}

TEST(PathFollower, FollowsARecordingFromItsOwnStart) {
  const CupPath path = scripted_path(4);
  EXPECT_LT(largest_x_error(path, path.states.front(), 0.0, {}), 0.01);
}

TEST(PathFollower, MovesThePathWithTheDice) {
  // The same recording from a start whose whole scene is 0.3 m to the left: the cup follows the
  // recorded x shifted by the dice' mean x.
  const CupPath path = scripted_path(4);
  State start = path.states.front();
  start[si::kCupX] -= 0.3;
  for (std::size_t i = 0; i < kDiceCount; ++i) start[si::die(i)] -= 0.3;
  EXPECT_NEAR(mean_dice_x(start) - mean_dice_x(path.states.front()), -0.3, 1e-12);
  EXPECT_LT(largest_x_error(path, start, -0.3, {}), 0.01);
}

TEST(PathFollower, HoldsTheLastPoseAfterThePathEnds) {
  const CupPath path = scripted_path(4);
  const PathFollower follower(path, {}, path.states.front(), 0, 10.0);
  // At rest on the last recorded pose, past the end, the feedback asks for nothing.
  State at_end = path.states.back();
  at_end[si::kCupVx] = at_end[si::kCupVy] = at_end[si::kCupW] = 0.0;
  const Action a = follower.act(at_end, static_cast<int>(path.states.size()) + 20);
  for (double v : a) EXPECT_NEAR(v, 0.0, 1e-9);
}

// A step's cup action read back from the states before and after it: exact while the cup
// touches nothing (here, lifted clear of the table and the dice, gravity pulling it).
TEST(PathFollower, ACupActionIsReadBackFromTheVelocitiesAroundItsStep) {
  DiceEnv env(WorldConfig{});
  State start = random_start_state(env.config(), 5);
  start[si::kCupY] += 1.0;
  env.reset_to(start, 0);
  const Action dv{0.3, -0.2, 0.4};
  const State before = env.get_state();
  env.step(dv);
  const Action read = cup_action_between(before, env.get_state(), env.config());
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(read[k], dv[k], 1e-4) << k;
}

TEST(TrackerRecordings, RefuseBadRecordingsNamingThem) {
  const WorldConfig w;
  EXPECT_THROW(Recordings({}, w, {}, 0), InputError);
  CupPath p = scripted_path(4);
  p.actions.pop_back();
  EXPECT_NE(test::error_of([&] { Recordings({p}, w, {}, 0); }).find(p.name), std::string::npos);
  p = scripted_path(4);
  p.states[7][5] = std::nan("");
  const std::string e = test::error_of([&] { Recordings({p}, w, {}, 0); });
  EXPECT_NE(e.find("\"scripted_4\" state 7"), std::string::npos) << e;
  TrackerConfig bad;
  bad.time_scale_range = 1.5;
  EXPECT_NE(test::error_of([&] { Recordings({scripted_path(4)}, w, bad, 0); }).find("time_scale_range"), std::string::npos);
}

TEST(TrackerRecordings, RankingDoesNotDependOnThreads) {
  const WorldConfig w = test::short_world(200);
  std::vector<CupPath> paths{scripted_path(1, w), scripted_path(2, w), scripted_path(3, w)};
  TrackerConfig c;
  c.probes = 4;
  const Recordings one(paths, w, c, 7, 1), two(paths, w, c, 7, 2);
  EXPECT_EQ(one.order(), two.order());
  EXPECT_EQ(one.probe_successes(), two.probe_successes());
  // keep: only the best-ranked recordings are ever tried, in the same order.
  c.paths = 2;
  const Recordings kept(paths, w, c, 7, 2);
  EXPECT_EQ(kept.order(), std::vector<std::size_t>(one.order().begin(), one.order().begin() + 2));
  c.paths = -1;
  EXPECT_NE(test::error_of([&] { Recordings(paths, w, c, 7); }).find("\"paths\""), std::string::npos);
}

TEST(ChoosePath, FindsARecordingThatSucceedsAndIsDeterministic) {
  const WorldConfig w;
  // Paths of successful scripted episodes; a start of one of them is a start some path succeeds from.
  const std::vector<CupPath> paths = successful_scripted_paths(3);
  TrackerConfig c;
  c.probes = 0;
  c.optimise = false;
  const Recordings r(paths, w, c, 0);
  DiceEnv env(w), sim(w);
  env.reset_to(paths[1].states.front());
  const TrackerChoice a = choose_path(r, env, sim, 3), b = choose_path(r, env, sim, 3);
  EXPECT_TRUE(a.success);
  EXPECT_EQ(a.path, b.path);
  EXPECT_EQ(a.simulations, b.simulations);
  EXPECT_TRUE(test::bit_equal(env.get_state(), paths[1].states.front()));  // the environment is not touched
}

TEST(ChoosePath, RobustTrialsKeepTheChoiceWhenTheyAreNoiselessAndPickTheMostRobustOtherwise) {
  const WorldConfig w;
  const std::vector<CupPath> paths = successful_scripted_paths(3);
  TrackerConfig c;
  c.probes = 0;
  c.optimise = false;
  DiceEnv env(w), sim(w);
  env.reset_to(paths[1].states.front());
  const TrackerChoice plain = choose_path(Recordings(paths, w, c, 0), env, sim, 3);
  ASSERT_TRUE(plain.success);
  // Trials without noise or warp replay the same episode: they all succeed, the choice stays,
  // and each costs one simulation.
  c.robust = 4;
  c.robust_noise = 0.0;
  const TrackerChoice noiseless = choose_path(Recordings(paths, w, c, 0), env, sim, 3);
  EXPECT_EQ(noiseless.path, plain.path);
  EXPECT_EQ(noiseless.simulations, plain.simulations + 4);
  // Trials that no path survives: every candidate is simulated, and the choice is still a success
  // as simulated (the one with most noisy successes; all have none, so the first), the same twice.
  c.robust_noise = 10.0;
  const Recordings hopeless(paths, w, c, 0);
  const TrackerChoice a = choose_path(hopeless, env, sim, 3), b = choose_path(hopeless, env, sim, 3);
  EXPECT_TRUE(a.success);
  EXPECT_EQ(a.path, b.path);
  EXPECT_EQ(a.simulations, b.simulations);
  EXPECT_GT(a.simulations, noiseless.simulations);
  EXPECT_EQ(a.path, plain.path);
  // Out of range: named.
  c.robust = -1;
  EXPECT_NE(test::error_of([&] { Recordings(paths, w, c, 0); }).find("\"robust\""), std::string::npos);
  c.robust = 1;
  c.robust_warp = 2.0;
  EXPECT_NE(test::error_of([&] { Recordings(paths, w, c, 0); }).find("\"robust_warp\""), std::string::npos);
}

TEST(ChoosePath, WhenNoRecordingSucceedsAsRecordedTheLeastNarrowingComesBeforeCmaes) {
  // Scripted paths moved to starts further right than they were recorded at: where none succeeds
  // as recorded, the shrink stage's choice is a narrowing on its grid (no offset, no time warp).
  const WorldConfig w;
  const std::vector<CupPath> paths = successful_scripted_paths(2);
  TrackerConfig c;
  c.probes = 0;
  c.shrink = 4;
  TrackerConfig as_recorded = c;
  as_recorded.optimise = false;
  const Recordings r(paths, w, c, 0), plain(paths, w, as_recorded, 0);
  DiceEnv env(w), sim(w);
  int narrowed = 0;
  for (const double shift : {0.6, 0.8, 1.0, 1.2, 1.4, 1.6}) {
    State start = paths[0].states.front();
    start[si::kCupX] += shift;
    for (std::size_t i = 0; i < kDiceCount; ++i) start[si::die(i)] += shift;
    env.reset_to(start);
    if (choose_path(plain, env, sim, 1).success) continue;
    const TrackerChoice a = choose_path(r, env, sim, 1);
    if (!a.success || a.warp.offset != 0.0) continue;  // CMA-ES's, after the grid failed
    EXPECT_EQ(a.warp.time_scale, 1.0);
    const double k = (1.0 - a.warp.amplitude) / c.amplitude_range * c.shrink;
    EXPECT_NEAR(k, std::round(k), 1e-9) << shift;
    EXPECT_GE(std::round(k), 1.0);
    ++narrowed;
  }
  EXPECT_GE(narrowed, 1) << "no start needed (and found) a narrowing";
  c.shrink = 101;
  EXPECT_NE(test::error_of([&] { Recordings(paths, w, c, 0); }).find("\"shrink\""), std::string::npos);
}

TEST(TrackerRecordings, RobustProbesScoreEachNoisyTrialThatSucceedsToo) {
  const WorldConfig w = test::short_world(200);
  std::vector<CupPath> paths{scripted_path(1, w), scripted_path(2, w), scripted_path(3, w)};
  TrackerConfig c;
  c.probes = 4;
  const Recordings plain(paths, w, c, 7, 1);
  // Noiseless trials: each success scores 1 + 3, the order stays.
  c.robust = 3;
  c.robust_noise = 0.0;
  const Recordings noiseless(paths, w, c, 7, 1);
  EXPECT_EQ(noiseless.order(), plain.order());
  for (std::size_t p = 0; p < paths.size(); ++p) EXPECT_EQ(noiseless.probe_successes()[p], 4 * plain.probe_successes()[p]);
  // Noisy trials are drawn per (path, probe, trial): the same on any number of threads.
  c.robust_noise = 0.1;
  c.robust_warp = 0.02;
  EXPECT_EQ(Recordings(paths, w, c, 7, 1).probe_successes(), Recordings(paths, w, c, 7, 2).probe_successes());
}

TEST(TrackerRecordings, VariantsOfTheBestRecordingsAreRankedAndTheFinalistsScoredAgainFromFreshStarts) {
  const WorldConfig w = test::short_world(200);
  std::vector<CupPath> paths{scripted_path(1, w), scripted_path(2, w), scripted_path(3, w)};
  TrackerConfig c;
  c.probes = 4;
  c.smooth = 2.0;
  const Recordings plain(paths, w, c, 7, 1);
  c.variants = {0.0, 2.0, 5.0};  // 2 is `smooth`'s: the recordings themselves
  c.variant_recordings = 2;
  c.finalists = 2;
  c.finalist_probes = 3;
  const Recordings r(paths, w, c, 7, 1);
  // The recordings as before, then the two best-ranked smoothed by 0 and by 5 steps.
  ASSERT_EQ(r.paths().size(), 3u + 2u * 2u);
  for (std::size_t p = 0; p < 3; ++p) {
    EXPECT_EQ(r.paths()[p].name, paths[p].name);
    // Their first scores are the plain ranking's; a finalist's grows by its second.
    if (r.probe_trials()[p] == 4) {
      EXPECT_EQ(r.probe_successes()[p], plain.probe_successes()[p]);
    } else {
      EXPECT_GE(r.probe_successes()[p], plain.probe_successes()[p]);
    }
  }
  const std::size_t best = plain.order()[0];
  EXPECT_EQ(r.paths()[3].name, paths[best].name + " (smoothed 0)");
  EXPECT_EQ(r.paths()[4].name, paths[best].name + " (smoothed 5)");
  EXPECT_EQ(r.paths()[3].states, paths[best].states);  // width 0: as recorded
  // Two finalists with 4 + 3 probe trials each lead the order, by their success rate.
  int finalists = 0;
  for (std::size_t p = 0; p < r.paths().size(); ++p) finalists += r.probe_trials()[p] == 7;
  EXPECT_EQ(finalists, 2);
  EXPECT_EQ(r.probe_trials()[r.order()[0]], 7);
  EXPECT_EQ(r.probe_trials()[r.order()[1]], 7);
  EXPECT_GE(r.probe_successes()[r.order()[0]], r.probe_successes()[r.order()[1]]);
  for (std::size_t k = 2; k < r.order().size(); ++k) EXPECT_EQ(r.probe_trials()[r.order()[k]], 4);
  // The same on any number of threads.
  const Recordings two(paths, w, c, 7, 2);
  EXPECT_EQ(two.order(), r.order());
  EXPECT_EQ(two.probe_successes(), r.probe_successes());
  c.variants = {-1.0};
  EXPECT_NE(test::error_of([&] { Recordings(paths, w, c, 7); }).find("\"variants\""), std::string::npos);
}

TEST(TrackerExpert, ChoosesOnceAndFollows) {
  const WorldConfig w;
  std::vector<CupPath> paths{scripted_path(5)};
  TrackerConfig c;
  c.probes = 0;
  c.optimise = false;
  ExpertConfig config;
  config.recordings = std::make_shared<const Recordings>(paths, w, c, 0);
  auto tracker = make_expert("tracker", config);
  EXPECT_EQ(tracker->name(), "tracker");
  {  // answering joint torques, it needs recordings whose simulations were told in them too
    ExpertConfig torques = config;
    torques.controller = ActionKind::joint_torque;
    EXPECT_THROW(make_expert("tracker", torques), ConfigError);
  }
  // From the recording's own start the tracker reproduces its cup path.
  DiceEnv env(w);
  env.reset_to(paths[0].states.front());
  tracker->reset(0);
  const ExpertEpisode e = run_expert_episode(*tracker, env, true);
  ASSERT_GE(e.states.size(), 50u);
  for (std::size_t t = 0; t < 50; ++t) EXPECT_NEAR(e.states[t][si::kCupX], paths[0].states[t][si::kCupX], 0.01) << t;
}

TEST(PathFollower, JoinsAPathMidwayAtItsPhase) {
  // A follower that starts at step 30 with the recorded steps the whole path's follower (started
  // at step 10) has played by then acts, from any state, as that follower does: at the recorded
  // pace and faster.
  const CupPath path = scripted_path(4);
  const State frame = path.states.front();
  for (const double pace : {1.0, 1.3}) {
    PathWarp warp;
    warp.time_scale = pace;
    const PathFollower whole(path, warp, frame, 10, 10.0);
    warp.phase = whole.phase(30);
    const PathFollower midway(path, warp, frame, 30, 10.0);
    EXPECT_DOUBLE_EQ(warp.phase, 20.0 * pace);
    EXPECT_EQ(midway.length(), whole.length() - 20) << pace;
    EXPECT_NEAR(midway.phase(45), 20.0 * pace + 15.0 * pace, 1e-9);
    for (const int step : {30, 47, 90, 1000})
      for (const std::size_t t : {std::size_t{3}, std::size_t{40}}) {
        const Action a = whole.act(path.states[t], step), b = midway.act(path.states[t], step);
        for (std::size_t k = 0; k < kActionDim; ++k) EXPECT_NEAR(a[k], b[k], 1e-9) << pace << " " << step << " " << t;
      }
  }
}

TEST(TrackerRecordings, SmoothRemovesAPersonsJitterAndKeepsTheMotion) {
  const WorldConfig w = test::short_world(100);
  CupPath path = scripted_path(4, w);
  const CupPath clean = path;
  // Step-to-step jitter in the pose and the action, as a hand on a mouse adds.
  for (std::size_t t = 0; t < path.states.size(); ++t) {
    const double sign = t % 2 ? 1.0 : -1.0;
    path.states[t][si::kCupY] += 0.01 * sign;
    path.actions[t][0] += 0.5 * sign;
  }
  TrackerConfig c;
  c.probes = 0;
  c.smooth = 4.0;
  const Recordings r({path}, w, c, 0), smooth_clean({clean}, w, c, 0);
  const CupPath& s = r.paths().front();
  const CupPath& sc = smooth_clean.paths().front();
  ASSERT_EQ(s.states.size(), path.states.size());
  double jitter = 0.0, drift = 0.0;
  for (std::size_t t = 0; t < s.states.size(); ++t) {
    EXPECT_EQ(s.actions[t][0], 0.0);  // the actions are folded into the velocities
    EXPECT_EQ(s.states[t][si::die(1)], path.states[t][si::die(1)]);  // the dice as recorded
    drift += std::abs(sc.states[t][si::kCupY] - clean.states[t][si::kCupY]) / static_cast<double>(s.states.size());
    if (t < 12 || t + 12 >= s.states.size()) continue;  // within 3 std of an end the window is one-sided
    jitter = std::max(jitter, std::abs(s.states[t][si::kCupVx] - sc.states[t][si::kCupVx]));
    jitter = std::max(jitter, std::abs(s.states[t][si::kCupY] - sc.states[t][si::kCupY]));
  }
  // The jitter (0.5 in the velocity, 1 cm in the pose) is gone: the noisy and the clean path
  // smooth to the same motion. The scripted path turns sharply, and smoothing it over 4 steps
  // moves its cup by 1.4 cm on average.
  EXPECT_LT(jitter, 1e-3);
  EXPECT_LT(drift, 0.02) << drift;
  // The velocity during a step is the state's plus the action's: the same path with its
  // actions moved into the states' velocities smooths to the same motion.
  CupPath moved = clean;
  for (std::size_t t = 0; t < moved.states.size(); ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      const std::size_t v = k == 0 ? si::kCupVx : k == 1 ? si::kCupVy : si::kCupW;
      moved.states[t][v] += moved.actions[t][k];
      moved.actions[t][k] = 0.0;
    }
  const Recordings smooth_moved({moved}, w, c, 0);
  for (std::size_t t = 0; t < sc.states.size(); ++t)
    EXPECT_NEAR(smooth_moved.paths().front().states[t][si::kCupVx], sc.states[t][si::kCupVx], 1e-9) << t;
  c.smooth = -1.0;
  EXPECT_NE(test::error_of([&] { Recordings({path}, w, c, 0); }).find("\"smooth\""), std::string::npos);
  c.smooth = 0.0;
  c.rescue = -1;
  EXPECT_NE(test::error_of([&] { Recordings({path}, w, c, 0); }).find("\"rescue\""), std::string::npos);
}

TEST(RescuePath, JoinsARecordingThatStillSucceedsFromAKnockedState) {
  // The tracker follows a scripted episode's path from its own start; at step 20 the cup is
  // knocked sideways and the path no longer stacks. A rescue from there joins another recording
  // whose continuation simulates to a success, and is deterministic.
  const WorldConfig w;
  const std::vector<CupPath> paths = successful_scripted_paths(3);
  TrackerConfig c;
  c.probes = 0;
  const Recordings r(paths, w, c, 0);
  DiceEnv env(w), sim(w);
  env.reset_to(paths[0].states.front());
  const State frame = env.get_state();
  const TrackerChoice current = choose_path(r, env, sim, 1);
  ASSERT_TRUE(current.success);
  const PathFollower follower(r.paths()[current.path], current.warp, frame, 0, c.gain);
  while (env.t() < 20) env.step(follower.act(env.get_state(), env.t()));
  env.step({0.6, 0.0, 0.0});  // the knock
  ASSERT_FALSE(still_succeeds(follower, env, sim, c.hold_steps, c.controller)) << "the knock did not matter";
  const TrackerChoice a = rescue_path(r, env, sim, frame, current, follower.phase(env.t()), 5);
  const TrackerChoice b = rescue_path(r, env, sim, frame, current, follower.phase(env.t()), 5);
  ASSERT_TRUE(a.success);
  EXPECT_NE(a.path, current.path);
  EXPECT_GT(a.warp.phase, 0.0) << "joined midway, not from the recording's start";
  EXPECT_EQ(a.path, b.path);
  EXPECT_EQ(a.warp.phase, b.warp.phase);
  EXPECT_EQ(a.simulations, b.simulations);
  EXPECT_TRUE(still_succeeds(PathFollower(r.paths()[a.path], a.warp, frame, env.t(), c.gain), env, sim, c.hold_steps, c.controller));
}

// The tracker's episode from paths[0]'s start, knocked at step 20 (dvx 0.6).
test::KnockedEpisode knocked_episode(const std::vector<CupPath>& paths, int rescue, bool retry) {
  const WorldConfig w;
  TrackerConfig c;
  c.probes = 0;
  c.rescue = rescue;
  ExpertConfig config;
  config.retry = retry;
  config.recordings = std::make_shared<const Recordings>(paths, w, c, 0);
  auto tracker = make_expert("tracker", config);
  tracker->reset(1);
  DiceEnv env(w);
  env.reset_to(paths[0].states.front());
  return test::knocked_episode(*tracker, env, 20, {0.6, 0.0, 0.0});
}

TEST(TrackerExpert, RescuesAKnockedEpisodeWhenAskedTo) {
  // The same knock as above, met by the expert itself: choosing once, it follows its path to a
  // failure; with a check every 5 steps it joins another recording and stacks, the same way twice.
  const std::vector<CupPath> paths = successful_scripted_paths(3);
  EXPECT_FALSE(knocked_episode(paths, 0, false).success) << "the knock breaks the path chosen once";
  const test::KnockedEpisode rescued = knocked_episode(paths, 5, false);
  EXPECT_TRUE(rescued.success);
  EXPECT_EQ(knocked_episode(paths, 5, false).actions, rescued.actions);
}

TEST(TrackerExpert, TriesAgainFromWhereAFailedAttemptCameToRestWhenAskedTo) {
  // The knock above, with the path chosen once: the attempt fails and its dice come to rest.
  // With retry the tracker chooses afresh there (attempt_start) and stacks the dice in time, the
  // same way twice, acting as before until then.
  const WorldConfig w;
  const std::vector<CupPath> paths = successful_scripted_paths(3);
  const test::KnockedEpisode once = knocked_episode(paths, 0, false);
  const std::size_t restart = attempt_start(once.states, w);
  EXPECT_FALSE(once.success) << "the knock breaks the path chosen once";
  EXPECT_GT(restart, 0u) << "and the failure comes to rest";
  const test::KnockedEpisode again = knocked_episode(paths, 0, true);
  EXPECT_TRUE(again.success);
  EXPECT_EQ(attempt_start(again.states, w), restart);
  ASSERT_GT(again.actions.size(), restart);
  for (std::size_t t = 0; t < restart; ++t) EXPECT_EQ(again.actions[t], once.actions[t]) << t;
  EXPECT_NE(again.actions[restart], once.actions[restart]) << "a new choice at the restart";
  EXPECT_EQ(knocked_episode(paths, 0, true).actions, again.actions);
}
}  // namespace
}  // namespace dicestack

namespace dicestack {
namespace {

using ::testing::HasSubstr;

TEST(TrackerPresets, PlainIsTheBareTrackerAndDistillTheLearnersTuning) {
  const TrackerConfig plain = tracker_preset("plain"), bare{};
  EXPECT_EQ(plain.paths, bare.paths);
  EXPECT_EQ(plain.smooth, bare.smooth);
  EXPECT_TRUE(plain.variants.empty());
  const TrackerConfig distill = tracker_preset("distill");
  EXPECT_EQ(distill.paths, 3);
  EXPECT_EQ(distill.smooth, 4.0);
  EXPECT_EQ(distill.robust, 5);
  EXPECT_EQ(distill.robust_warp, 0.02);
  EXPECT_EQ(distill.shrink, 5);
  EXPECT_EQ(distill.variants.size(), kTrackerVariantWidths.size());
  EXPECT_EQ(distill.refine, 60);
  EXPECT_EQ(plain.refine, 0);
  EXPECT_NO_THROW(validate(distill));
  EXPECT_THAT(test::error_of([] { tracker_preset("tuned"); }),
              HasSubstr("tracker preset \"tuned\": unknown; presets: plain, distill"));
}

TEST(TrackerPresets, InJointTorquesATrackerIsNotRefinedAndRanksFromMoreStartsUnlessTold) {
  TrackerConfig settled = tracker_preset("distill");
  settle_for_joint_torques(settled, [](std::string_view) { return false; });
  EXPECT_EQ(settled.controller, ActionKind::joint_torque);
  EXPECT_EQ(settled.refine, 0);
  EXPECT_EQ(settled.probes, 32);
  EXPECT_EQ(settled.finalist_probes, 128);
  TrackerConfig told = tracker_preset("distill");
  told.probes = 8;
  told.refine = 3;
  settle_for_joint_torques(told, [](std::string_view name) { return name == "probes" || name == "refine"; });
  EXPECT_EQ(told.probes, 8);
  EXPECT_EQ(told.refine, 3);
}

TEST(TrackerPresets, SettingsGoOnTopByTheirFieldsNamesAndABadOneIsNamed) {
  const TrackerConfig c = tracker_config("distill", {"smooth=2", "variants=false", "probes=8", "paths=1"});
  EXPECT_EQ(c.smooth, 2.0);
  EXPECT_TRUE(c.variants.empty());
  EXPECT_EQ(c.probes, 8);
  EXPECT_EQ(c.finalist_probes, 32) << "finalists are scored from four times the ranking's starts";
  EXPECT_EQ(c.paths, 1);
  EXPECT_EQ(c.robust, 5) << "the preset's, not given";
  for (const auto& name : tracker_setting_names()) {
    TrackerConfig t;
    EXPECT_THAT(test::error_of([&] { set_tracker_setting(t, name, "x"); }), HasSubstr("tracker setting " + name + ": takes"))
        << name;
  }
  EXPECT_THAT(test::error_of([] { tracker_config("plain", {"smoth=2"}); }),
              HasSubstr("tracker setting \"smoth\": unknown; settings: probes, optimise, paths"));
  EXPECT_THAT(test::error_of([] { tracker_config("plain", {"smooth"}); }), HasSubstr("give NAME=VALUE"));
  EXPECT_THAT(test::error_of([] { tracker_config("plain", {"robust=-2"}); }), HasSubstr("robust"));
}

}  // namespace
}  // namespace dicestack
