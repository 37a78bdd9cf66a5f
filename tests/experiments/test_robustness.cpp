// The robustness table: a row per factor and level, the same on any thread count, rendered in the
// leaderboard's formats, and its html page.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/experiments/results_page.hpp>
#include <dicestack/experiments/robustness.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/pages.hpp>
#include <dicestack/test/policies.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::page_data;
using test::read;
using test::Watcher;
using test::watcher;

TEST(Robustness, RowsCoverEveryFactorAndLevelAndAreThreadIndependent) {
  RobustnessRequest r;
  r.episodes = 2;
  r.seed = 3;
  r.threads = 1;
  const WorldConfig w = test::short_world(25);
  const auto one = robustness(watcher, w, r);
  ASSERT_EQ(one.size(), 1 + 3 * perturbation_factors().size() + 3);
  EXPECT_EQ(one.front().factor, "none");
  EXPECT_EQ(one.back().factor, "all");
  EXPECT_EQ(one.back().level, "hard");
  r.threads = 2;
  const auto two = robustness(watcher, w, r);
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].stats.dice_in_cup_mean, two[i].stats.dice_in_cup_mean) << one[i].factor << one[i].level;
    EXPECT_EQ(one[i].stats.realistic_success.value, two[i].stats.realistic_success.value);
  }
  r.reads_world = true;  // an expert: the sensing factors are left out
  EXPECT_EQ(robustness(watcher, w, r).size(), 1 + 3 * (perturbation_factors().size() - 2) + 3);
}

TEST(Robustness, FactorsChooseTheRowsInTheTablesOrderAndAnUnknownOneIsRefusedFirst) {
  RobustnessRequest r;
  r.episodes = 2;
  r.seed = 3;
  r.threads = 1;
  const WorldConfig w = test::short_world(25);
  const auto all = robustness(watcher, w, r);
  r.factors = {"action_delay", "none"};
  const auto some = robustness(watcher, w, r);
  ASSERT_EQ(some.size(), 4u);
  EXPECT_EQ(some[0].factor, "none");
  for (std::size_t i = 1; i < 4; ++i) {
    EXPECT_EQ(some[i].factor, "action_delay");
    const auto same = std::find_if(all.begin(), all.end(), [&](const RobustnessRow& row) {
      return row.factor == some[i].factor && row.level == some[i].level;
    });
    ASSERT_NE(same, all.end());
  }
  r.reads_world = true;  // an expert: sensing rows alone leave nothing to measure
  r.factors = {"observation_noise"};
  EXPECT_THAT(test::error_of([&] { robustness(watcher, w, r); }), HasSubstr("no row to measure"));
  r.reads_world = false;
  std::atomic<int> made{0};
  r.factors = {"none", "wind"};
  EXPECT_THAT(test::error_of([&] {
                robustness([&] { ++made; return std::make_unique<Watcher>(); }, w, r);
              }),
              HasSubstr("unknown factor \"wind\""));
  EXPECT_EQ(made, 0);
}

TEST(Robustness, RendersTheLeaderboardsFormats) {
  RobustnessRow row{"friction", "hard", {}};
  row.stats.episodes = 10;
  row.stats.realistic_success = wilson(7, 10);
  RobustnessRun run;
  run.policy = "model m.dsm (knn, state)";
  run.episodes = 10;
  run.seed = 3;
  const RobustnessTable table = robustness_table({row}, run);
  EXPECT_THAT(table.header, HasSubstr("dicestack robustness: model m.dsm (knn, state); 10 rollouts per row"));
  EXPECT_THAT(render_robustness(table, "md"), HasSubstr("| friction | hard | 70% ["));
  EXPECT_THAT(render_robustness(table, "csv"), HasSubstr("\nfriction,hard,0.7,"));
  const auto j = nlohmann::json::parse(render_robustness(table, "json"));
  EXPECT_EQ(j["format"], "dicestack-robustness");
  EXPECT_EQ(j["rows"][0]["realistic_success_rate"], 0.7);
  EXPECT_EQ(j["header"], table.header);
  EXPECT_EQ(j["policy"], "model m.dsm (knn, state)");
  EXPECT_EQ(j["world"], "default");
  EXPECT_EQ(j["seed"], 3);
  EXPECT_FALSE(j.contains("sensing_factors")) << "a model reads the observations";
  EXPECT_THAT(render_robustness(table, "html"), HasSubstr("<!doctype html>"));
  EXPECT_THAT(test::error_of([&] { render_robustness(table, "pdf"); }), HasSubstr("md, csv, json, html"));
}

TEST(Robustness, EachFormatHasOneEntryAndReplacesOnlyItsOwnFiles) {
  const auto dir = test::scratch_path("dicestack_robustness_formats");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  RobustnessRow row{"none", "none", {}};
  row.stats.episodes = 2;
  const RobustnessTable table = robustness_table({row}, {});
  std::set<std::string> names, suffixes;
  for (const RobustnessFormat& f : robustness_formats()) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_TRUE(suffixes.insert(f.suffix).second) << f.name;
    const auto out = dir / ("table" + f.suffix);
    write_robustness(table, f.name, out);
    EXPECT_TRUE(f.ownership().recognises(out)) << f.name;
    check_robustness_out(out, f.name);  // ours: may be replaced
    std::ofstream(out) << "my notes\n";
    EXPECT_THROW(check_robustness_out(out, f.name), InputError) << f.name;
    EXPECT_THROW(write_robustness(table, f.name, out), InputError) << f.name;
    std::ifstream in(out);
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line, "my notes") << f.name;
  }
  EXPECT_EQ(names, (std::set<std::string>{"md", "csv", "json", "html"}));
  std::filesystem::remove_all(dir);
}

// A robustness table of three rows, run by `policy`, with `record` as the model's training record.
RobustnessTable robustness_example(const std::string& policy, const std::map<std::string, std::string>& record = {}) {
  std::vector<RobustnessRow> rows;
  const std::vector<std::pair<const char*, const char*>> names{{"none", "none"}, {"friction", "hard"}, {"all", "easy"}};
  for (std::size_t i = 0; i < names.size(); ++i) {
    RobustnessRow r{names[i].first, names[i].second, {}};
    r.stats.episodes = 4;
    r.stats.realistic_success = wilson(3 - static_cast<int>(i), 4);
    r.stats.wall_contact = wilson(static_cast<int>(i), 4);
    r.stats.dice_in_cup_mean = 3.0 - 0.5 * static_cast<double>(i);
    rows.push_back(r);
  }
  RobustnessRun run;
  run.policy = policy;
  run.world = "short.json";
  run.episodes = 4;
  run.seed = 7;
  run.record = record;
  return robustness_table(rows, run);
}

TEST(RobustnessPage, HoldsTheJsonRowsAndTheRunsFactsWithNoNetwork) {
  const RobustnessTable table = robustness_example("model m.dsm (knn, state)", {{"learner", "bc"}});
  const std::string page = render_robustness(table, "html");
  EXPECT_EQ(page.rfind(std::string(kResultsPageMarker) + "\n<!doctype html>", 0), 0u);
  for (const char* remote : {"http://", "https://", "//cdn", "<link", "src="}) EXPECT_EQ(page.find(remote), std::string::npos) << remote;
  const auto data = page_data(page);
  const auto json = nlohmann::json::parse(render_robustness(table, "json"));
  EXPECT_EQ(data["title"], "dicestack robustness: model m.dsm (knn, state)");
  EXPECT_EQ(data["header"], json["header"]);
  ASSERT_EQ(data["rows"].size(), json["rows"].size());
  for (std::size_t i = 0; i < data["rows"].size(); ++i) {
    const auto& shown = data["rows"][i];
    for (const auto& [key, value] : json["rows"][i].items()) EXPECT_EQ(shown[key], value) << key;  // the json row, whole
    EXPECT_EQ(shown["rank"], i + 1);
    const auto& ci = json["rows"][i]["realistic_success_rate_ci95"];
    EXPECT_EQ(shown["realistic_success_ci95"], (nlohmann::json{ci[1], ci[2]})) << "the interval the page shows";
    EXPECT_EQ(shown["successes"], 3 - static_cast<int>(i));
  }
  std::map<std::string, nlohmann::json> facts;
  for (const auto& f : data["facts"]) facts[f[0]] = f[1];
  EXPECT_EQ(facts["policy"], "model m.dsm (knn, state)");
  EXPECT_EQ(facts["world"], "short.json");
  EXPECT_EQ(facts["rollouts_per_row"], 4);
  EXPECT_EQ(facts["seed"], 7);
  EXPECT_EQ(facts["dicestack_version"], json["dicestack_version"]);
  EXPECT_EQ(facts["model_record"], (nlohmann::json{{"learner", "bc"}}));
  EXPECT_EQ(facts.count("sensing_factors"), 0u);
}

TEST(RobustnessPage, TextFromTheModelAndTheSetCannotCloseItsScript) {
  const std::string hostile = "</script><script>alert(1)</script>";
  const RobustnessTable table = robustness_example("model " + hostile, {{"demos", "<!-- & -->"}});
  const std::string page = render_robustness(table, "html");
  EXPECT_EQ(page.find("alert(1)</script>"), std::string::npos);
  EXPECT_EQ(page.find("<!-- & -->"), std::string::npos);
  const auto data = page_data(page);
  EXPECT_EQ(data["title"], "dicestack robustness: model " + hostile);
  EXPECT_THAT(data["header"].get<std::string>(), ::testing::HasSubstr(hostile));
  bool record = false;
  for (const auto& f : data["facts"]) record |= f[0] == "model_record" && f[1]["demos"] == "<!-- & -->";
  EXPECT_TRUE(record);
}

TEST(RobustnessPage, ReplacesOnlyAPageOfOursAndLeavesNothingBeside) {
  const fs::path dir = test::scratch_path("dicestack_robustness_page_test");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "robust.html";
  write_robustness(robustness_example("expert scripted"), "html", out);
  EXPECT_TRUE(results_page_ownership().recognises(out));
  write_robustness(robustness_example("expert mpc"), "html", out);  // ours: replaced
  EXPECT_NE(read(out).find("expert mpc"), std::string::npos);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "one file, no media folder";
  std::ofstream(out) << "<p>mine</p>";
  EXPECT_THROW(check_robustness_out(out, "html"), InputError);
  EXPECT_THROW(write_robustness(robustness_example("expert mpc"), "html", out), InputError);
  EXPECT_EQ(read(out), "<p>mine</p>");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace dicestack
