// The learning curve: realistic success against the number of recordings a policy learns from.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/experiments/learning_curve.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

std::vector<Episode> numbered(std::size_t n) {
  std::vector<Episode> out(n);
  for (std::size_t i = 0; i < n; ++i) out[i].name = "episode_" + std::to_string(i);
  return out;
}

TEST(LearningCurve, ADrawIsKOfTheSetInItsOrderTheSameForItsSeedAndAllOfItAtItsSize) {
  const std::vector<Episode> set = numbered(20);
  const auto a = draw_recordings(set, 5, 3), again = draw_recordings(set, 5, 3), other = draw_recordings(set, 5, 4);
  ASSERT_EQ(a.size(), 5u);
  std::set<std::string> names;
  for (std::size_t i = 0; i < a.size(); ++i) {
    names.insert(a[i].name);
    EXPECT_EQ(a[i].name, again[i].name);
    if (i > 0) {
      EXPECT_LT(std::stoi(a[i - 1].name.substr(8)), std::stoi(a[i].name.substr(8)));  // the set's order
    }
  }
  EXPECT_EQ(names.size(), 5u);  // without replacement
  bool differs = false;
  for (std::size_t i = 0; i < a.size(); ++i) differs |= a[i].name != other[i].name;
  EXPECT_TRUE(differs);
  EXPECT_EQ(draw_recordings(set, 20, 3).size(), 20u);
  EXPECT_EQ(draw_recordings(set, 50, 3).size(), 20u);
  EXPECT_THROW(draw_recordings(set, 0, 3), ConfigError);
}

// A small set in a short world: scripted-expert episodes.
std::filesystem::path small_set() {
  static const std::filesystem::path dir = [] {
    const auto d = test::scratch_path("dicestack_curve_set");
    std::filesystem::remove_all(d);
    DemoSet set;
    set.world = test::short_world();
    set.description = "curve test";
    set.episodes = record_expert("scripted", {}, set.world, test::record_request(4, 2, 1));
    write_demo_set(set, d);
    return d;
  }();
  return dir;
}

LearningCurveRequest small_request(int threads) {
  LearningCurveRequest r;
  r.world = test::short_world();
  r.demos = small_set();
  r.recordings = {3, 1, 9};
  r.draws = 2;
  r.learners = {"bc"};
  r.regressors = {"knn", "linear_svr"};
  r.episodes = 3;
  r.seed = 5;
  r.threads = threads;
  return r;
}

TEST(LearningCurve, EveryLearnerAndRegressorLearnsEachDrawAloneTheSameOnAnyNumberOfThreads) {
  const LearningCurve one = run_learning_curve(small_request(1)), two = run_learning_curve(small_request(2));
  // 1 and 3 recordings: 2 draws each; 9 is more than the 4 there are: the whole set, once.
  ASSERT_EQ(one.points.size(), (2u + 2u + 1u) * 2u);
  ASSERT_EQ(two.points.size(), one.points.size());
  std::vector<int> counts;
  for (std::size_t i = 0; i < one.points.size(); ++i) {
    const LearningCurvePoint& p = one.points[i];
    counts.push_back(p.recordings);
    EXPECT_EQ(p.names.size(), static_cast<std::size_t>(p.recordings));
    EXPECT_EQ(p.episodes, 3);
    EXPECT_EQ(p.success.value, two.points[i].success.value);
    EXPECT_EQ(p.dice_in_cup, two.points[i].dice_in_cup);
    EXPECT_EQ(p.names, two.points[i].names);
  }
  EXPECT_EQ(counts, (std::vector<int>{1, 1, 1, 1, 3, 3, 3, 3, 4, 4}));
  EXPECT_EQ(one.points[0].draw_seed, 5u);
  EXPECT_EQ(one.points[2].draw_seed, 6u);
  // A draw is the one `dataset subset` writes for the same number and seed.
  EXPECT_EQ(one.points[2].names[0], draw_recordings(read_demo_set(small_set()).episodes, 1, 6)[0].name);
}

TEST(LearningCurve, BadRequestsAreRefusedBeforeAnyWork) {
  auto refused = [](auto change, const char* words) {
    LearningCurveRequest r = small_request(1);
    change(r);
    EXPECT_THAT(test::error_of([&] { run_learning_curve(r); }), HasSubstr(words));
  };
  refused([](auto& r) { r.recordings = {}; }, "at least one number");
  refused([](auto& r) { r.recordings = {0}; }, "[1, 1000000]");
  refused([](auto& r) { r.draws = 0; }, "draws");
  refused([](auto& r) { r.learners = {"dartt"}; }, "dartt");
  refused([](auto& r) { r.regressors = {"svm"}; }, "svm");
  refused([](auto& r) { r.episodes = 2000000000; }, "rollouts would need");
}

TEST(LearningCurve, EachFormatCarriesItsMarkerAndOnlyACurveIsReplaced) {
  LearningCurve c;
  c.header = "a <curve>";
  LearningCurvePoint p;
  p.learner = "dart:expert=tracker";
  p.regressor = "gbt";
  p.recordings = 3;
  p.names = {"episode_0001", "episode_0007"};
  p.episodes = 100;
  p.success = {0.85, 0.77, 0.91};
  c.points = {p};
  const std::string md = render_learning_curve(c, "md");
  EXPECT_EQ(md.rfind("<!-- dicestack learning curve -->", 0), 0u);
  EXPECT_THAT(md, HasSubstr("| dart:expert=tracker | gbt | 3 | 1 | 85% | 85% | 85% |"));
  // A long list of followed paths stays whole, its row closed.
  LearningCurve many = c;
  many.points[0].followed = std::string(3000, 'f');
  EXPECT_THAT(render_learning_curve(many, "md"), HasSubstr(" | " + std::string(3000, 'f') + " |\n"));
  EXPECT_EQ(render_learning_curve(c, "csv").rfind("learner,regressor,recordings,draw_seed", 0), 0u);
  const auto j = nlohmann::json::parse(render_learning_curve(c, "json"));
  EXPECT_EQ(j["format"], "dicestack-learning-curve");
  EXPECT_EQ(j["points"][0]["recordings_drawn"][1], "episode_0007");
  const std::string html = render_learning_curve(c, "html");
  EXPECT_THAT(html, HasSubstr("<svg"));
  EXPECT_THAT(html, HasSubstr("a &lt;curve&gt;"));
  EXPECT_THROW(render_learning_curve(c, "latex"), ConfigError);

  const auto out = test::scratch_path("dicestack_curve.md");
  std::filesystem::remove(out);
  for (const char* format : {"md", "csv", "json", "html"}) write_learning_curve(c, format, out);  // each replaces the last
  { std::ofstream(out) << "my notes\n"; }
  EXPECT_THROW(write_learning_curve(c, "md", out), InputError);
  EXPECT_THROW(check_learning_curve_replaceable(out), InputError);
  std::ifstream in(out);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "my notes");
  std::filesystem::remove(out);
}

}  // namespace
}  // namespace dicestack
