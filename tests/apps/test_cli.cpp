#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <algorithm>
#include <sstream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>
#include <chrono>
#include <iterator>

#include <gif_lib.h>
#include <nlohmann/json.hpp>

#include <dicestack/core/env.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/perturbation.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/features.hpp>
#include <dicestack/version.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

struct Process {
  int status = -1;
  std::string output;  // stdout and stderr
};

// Runs the shell command `cmd`; stderr joins stdout unless `keep_stderr` is false.
Process run_command(const std::string& cmd, bool keep_stderr) {
  Process r;
  FILE* pipe = popen((cmd + (keep_stderr ? " 2>&1" : " 2>/dev/null")).c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) r.output.append(buf, n);
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

// Runs dicestack with `args`; stderr joins stdout unless `keep_stderr` is false.
Process run(const std::string& args, bool keep_stderr = true) {
  return run_command(std::string(DICESTACK_EXE) + " " + args, keep_stderr);
}

// As run, killed after `seconds` (exit status 124): a command that would hang fails instead.
Process run_within(int seconds, const std::string& args) {
  return run_command("timeout -k 2 " + std::to_string(seconds) + " " + std::string(DICESTACK_EXE) + " " + args, true);
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A file's whole text.
std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(Cli, VersionAndHelp) {
  const Process v = run("--version");
  EXPECT_EQ(v.status, 0);
  EXPECT_THAT(v.output, HasSubstr("dicestack " DICESTACK_VERSION));
  const Process h = run("--help");
  EXPECT_EQ(h.status, 0);
  EXPECT_THAT(h.output, HasSubstr("bench"));
  EXPECT_THAT(h.output, HasSubstr("rollout"));
  EXPECT_EQ(run("rollout --help").status, 0);
  EXPECT_EQ(run("bench sim --help").status, 0);
}

TEST(Cli, UsageErrorsExitNonZero) {
  EXPECT_NE(run("").status, 0);
  EXPECT_NE(run("no-such-command").status, 0);
  EXPECT_NE(run("rollout --steps -3").status, 0);
}

TEST(Cli, SeedsOutsideTheirRangeAreRefusedNotWrapped) {
  for (const char* seed : {"-1", "18446744073709551616", "1e3", "3.5", "010"}) {
    const Process p = run(std::string("rollout --steps 1 --seed ") + seed);
    EXPECT_NE(p.status, 0) << seed;
    EXPECT_THAT(p.output, HasSubstr("a seed is a whole number in [0, 18446744073709551615]")) << seed;
  }
  EXPECT_EQ(run("rollout --steps 1 --seed 18446744073709551615").status, 0);
  EXPECT_NE(run("evaluate --model x.dsm --seed -1").status, 0);
}

TEST(Cli, StateHashIsIdenticalAcrossProcessesAndMatchesThisOne) {
  const Process a = run("rollout --seed 9 --steps 300 --json");
  const Process b = run("rollout --seed 9 --steps 300 --json");
  ASSERT_EQ(a.status, 0) << a.output;
  const auto ja = nlohmann::json::parse(a.output), jb = nlohmann::json::parse(b.output);
  EXPECT_EQ(ja["state_hash"], jb["state_hash"]);
  EXPECT_EQ(ja["steps"], 300);

  // The same episode in this process: random start from the seed, actions from stream 2.
  const WorldConfig c;
  DiceEnv env(c);
  std::uint64_t hash = hash_state(env.reset(9));
  Rng rng(derive_seed(9, 2));
  for (int t = 0; t < 300; ++t) {
    Action act;
    for (std::size_t k = 0; k < kActionDim; ++k) act[k] = rng.uniform(-1.0, 1.0) * c.action.scale[k];
    hash = hash_state(env.step(act).observation, hash);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  EXPECT_EQ(ja["state_hash"], hex);
  EXPECT_NE(ja["state_hash"], nlohmann::json::parse(run("rollout --seed 10 --steps 300 --json").output)["state_hash"]);
}

TEST(Cli, RolloutDrivesTheArmsJointsInTorquesAndOnlyTheArms) {
  const Process limp = run("rollout --embodiment arm --controller joint_torque --actions still --steps 20 --json", false);
  ASSERT_EQ(limp.status, 0) << limp.output;
  const Process held = run("rollout --embodiment arm --actions still --steps 20 --json", false);
  ASSERT_EQ(held.status, 0) << held.output;
  EXPECT_NE(nlohmann::json::parse(limp.output)["state_hash"], nlohmann::json::parse(held.output)["state_hash"])
      << "no torque lets the arm fall; the cup controller holds the cup";
  const Process random = run("rollout --embodiment arm --controller joint_torque --steps 20 --json", false);
  ASSERT_EQ(random.status, 0) << random.output;
  const Process cup = run("rollout --controller joint_torque --steps 2");
  EXPECT_EQ(cup.status, 1);
  EXPECT_THAT(cup.output, HasSubstr("give --embodiment arm"));
}

TEST(Cli, BadWorldConfigIsReportedWithTheField) {
  const auto good = test::scratch_path("dicestack_cli_world.json");
  ASSERT_EQ(run("config --out " + good.string()).status, 0);
  auto j = nlohmann::json::parse(std::ifstream(good));
  j["physics"]["substeps"] = -2;
  const auto bad = test::scratch_path("dicestack_cli_world_bad.json");
  std::ofstream(bad) << j.dump();
  const Process r = run("rollout --world " + bad.string());
  EXPECT_EQ(r.status, 1);
  EXPECT_THAT(r.output, HasSubstr("dicestack: error: world config " + bad.string()));
  EXPECT_THAT(r.output, HasSubstr("\"physics.substeps\""));
  const Process check = run("config --check " + bad.string());
  EXPECT_EQ(check.status, 1);
  EXPECT_EQ(run("config --check " + good.string()).status, 0);
  std::filesystem::remove(good);
  std::filesystem::remove(bad);
}

// `--embodiment arm` puts the arm under any world; a world whose arm cannot hold the cup at its
// start is refused naming the field, and an unknown embodiment naming the choices.
TEST(Cli, TheEmbodimentIsChosenOnAnyWorld) {
  const Process held = run("rollout --steps 5 --embodiment arm --json", false);
  EXPECT_EQ(held.status, 0) << held.output;
  EXPECT_EQ(run("rollout --steps 5 --json", false).output.size() > 0, true);
  const auto file = test::scratch_path("dicestack_cli_short_arm.json");
  ASSERT_EQ(run("config --out " + file.string()).status, 0);
  auto j = nlohmann::json::parse(std::ifstream(file));
  j["arm"]["link_lengths"] = {1.0, 1.0, 0.5};
  std::ofstream(file) << j.dump();
  EXPECT_EQ(run("rollout --steps 5 --world " + file.string()).status, 0);  // a cup world never reads its arm
  const Process short_arm = run("rollout --steps 5 --embodiment arm --world " + file.string());
  EXPECT_EQ(short_arm.status, 1);
  EXPECT_THAT(short_arm.output, HasSubstr("--embodiment arm: world config <value>: field \"arm.link_lengths\" cannot reach"));
  const Process unknown = run("rollout --steps 5 --embodiment robot");
  EXPECT_NE(unknown.status, 0);
  EXPECT_THAT(unknown.output, HasSubstr("robot not in {cup,arm}"));
  std::filesystem::remove(file);
}

// Every file a user names goes through one checked reader: a FIFO (which would block at its
// open) or a device (which never ends) is refused at once, naming the file, by every command.
TEST(CliInput, AFifoOrADeviceGivenForAnyFileIsRefusedAtOnce) {
  namespace fs = std::filesystem;
  const fs::path dir = test::scratch_path("dicestack_cli_fifo");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // A set whose meta.json is a FIFO, and one whose episode is.
  const fs::path good = fs::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good";
  for (const char* set : {"meta_fifo", "episode_fifo"}) fs::copy(good, dir / set);
  fs::remove(dir / "meta_fifo" / "meta.json");
  ASSERT_EQ(::mkfifo((dir / "meta_fifo" / "meta.json").c_str(), 0600), 0);
  fs::remove(dir / "episode_fifo" / "episode_0000.csv");
  ASSERT_EQ(::mkfifo((dir / "episode_fifo" / "episode_0000.csv").c_str(), 0600), 0);
  const std::string f = fifo.string(), out = (dir / "out").string();
  const std::vector<std::pair<std::string, std::string>> cases{
      {"rollout --steps 1 --world " + f, f},
      {"evaluate --episodes 1 --model " + f, f},
      {"evaluate --episodes 1 --model /dev/zero", "/dev/zero"},
      {"record --expert scripted --episodes 1 --perturb " + f + " --out " + out, f},
      {"config --check " + f, f},
      {"dataset info " + (dir / "meta_fifo").string(), (dir / "meta_fifo" / "meta.json").string()},
      {"dataset validate " + (dir / "episode_fifo").string(), (dir / "episode_fifo" / "episode_0000.csv").string()},
      {"train --regressor knn --split none --demos " + (dir / "episode_fifo").string() + " --out " + out + ".dsm",
       (dir / "episode_fifo" / "episode_0000.csv").string()}};
  for (const auto& [args, file] : cases) {
    // `timeout` turns a hang into a failure (exit 124) rather than a stuck suite.
    const Process p = run_within(20, args);
    EXPECT_EQ(p.status, 1) << args << "\n" << p.output;
    EXPECT_THAT(p.output, HasSubstr(file + ": not a regular file (")) << args;
  }
  EXPECT_FALSE(fs::exists(dir / "out")) << "nothing written";
  fs::remove_all(dir);
}

// A key given twice in a JSON file a user writes is refused, naming the file and the key,
// instead of the last one silently winning.
TEST(CliInput, AKeyGivenTwiceInAnyJsonFileIsRefusedNamingIt) {
  namespace fs = std::filesystem;
  const fs::path dir = test::scratch_path("dicestack_cli_twice");
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path perturbation = dir / "p.json", world = dir / "w.json", set = dir / "set";
  std::ofstream(perturbation) << R"({"format": "dicestack-perturbation", "version": 2, "gravity": 0.4, "gravity": 0})";
  ASSERT_EQ(run("config --out " + world.string()).status, 0);
  {
    std::string text = read_text(world);
    text.insert(text.find('{') + 1, "\"episode\": {}, ");
    std::ofstream(world) << text;
  }
  fs::copy(fs::path(DICESTACK_SOURCE_DIR) / "tests/datasets/data/good", set);
  {
    std::string text = read_text(set / "meta.json");
    text.insert(text.find('{') + 1, "\"format\": \"x\", ");
    std::ofstream(set / "meta.json") << text;
  }
  const std::vector<std::tuple<std::string, std::string, std::string>> cases{
      {"record --expert scripted --episodes 1 --perturb " + perturbation.string() + " --out " + (dir / "out").string(),
       perturbation.string(), "gravity"},
      {"rollout --steps 1 --world " + world.string(), world.string(), "episode"},
      {"dataset info " + set.string(), (set / "meta.json").string(), "format"}};
  for (const auto& [args, file, key] : cases) {
    const Process p = run_within(20, args);
    EXPECT_EQ(p.status, 1) << args << "\n" << p.output;
    EXPECT_THAT(p.output, HasSubstr(file)) << args;
    EXPECT_THAT(p.output, HasSubstr("key \"" + key + "\" appears twice in one object")) << args;
  }
  fs::remove_all(dir);
}

// A value far longer than any name (a pasted file, a runaway script) is cut in the message,
// whichever parser refuses it: the message stays readable, the value's start and end shown.
TEST(CliInput, AnOverlongValueInAnyOptionIsCutInTheMessage) {
  const std::string v(50000, 'v');
  const std::string out = " --out " + test::scratch_path("dicestack_cli_overlong.dsm").string();
  const std::vector<std::string> cases{"train --regressor knn --set k=" + v + out,
                                       "train --regressor " + v + out,
                                       "train --regressor knn --learner dart --option expert=" + v + out,
                                       "train --regressor knn --features state+" + v + out,
                                       "leaderboard --learners dart:" + v,
                                       "train --regressor knn --episodes " + v + out,
                                       "evaluate --model /nonexistent/" + v};
  for (const auto& args : cases) {
    const Process p = run_within(20, args);
    EXPECT_NE(p.status, 0) << args.substr(0, 60);
    EXPECT_LT(p.output.size(), 2000u) << args.substr(0, 60) << "\n" << p.output.substr(0, 400);
    EXPECT_THAT(p.output, HasSubstr("characters cut]...")) << args.substr(0, 60) << "\n" << p.output.substr(0, 400);
  }
}

// The estimator is chosen by name at the edge: a bad name, or an estimator for an expert whose
// feedback reads the world, is refused before any rollout; `none` changes no byte, and without
// sensing factors the policy sees the state whatever the estimator.
TEST(CliInput, TheEstimatorIsCheckedFirstAndNoneChangesNothing) {
  const Process bad = run_within(5, "robustness --expert scripted --estimator particles --episodes 1");
  EXPECT_NE(bad.status, 0);
  EXPECT_THAT(bad.output, HasSubstr("--estimator"));
  const Process none_left = run_within(5, "robustness --expert scripted --estimator particle:0 --episodes 1");
  EXPECT_NE(none_left.status, 0);
  EXPECT_THAT(none_left.output, HasSubstr("a count of particles from 1 to 4096"));
  const Process world = run_within(5, "robustness --expert scripted --estimator kalman --episodes 1");
  EXPECT_EQ(world.status, 1);
  EXPECT_THAT(world.output, HasSubstr("--expert-feedback observations"));
  const std::string base =
      "robustness --expert scripted --expert-feedback observations --factors none,observation_delay --episodes 3";
  const Process plain = run(base, false), none = run(base + " --estimator none", false),
                kalman = run(base + " --estimator kalman", false);
  ASSERT_EQ(plain.status, 0) << plain.output;
  EXPECT_EQ(plain.output, none.output);
  EXPECT_THAT(kalman.output, HasSubstr("the kalman estimator's estimate"));
  // A delay in the nominal world is made up exactly: each delay row is the nominal row.
  const auto rates = [](const std::string& out, const std::string& row) {
    const auto at = out.find(row);
    return at == std::string::npos ? std::string("missing") : out.substr(at + row.size(), out.find('\n', at) - at - row.size());
  };
  const std::string nominal = rates(kalman.output, "| none | none |");
  for (const std::string level : {"easy", "medium", "hard"})
    EXPECT_EQ(rates(kalman.output, "| observation_delay | " + level + " |"), nominal) << level;
}

// The reference pages are generated from the code: each committed page, up to its hand-written
// version history, is what `dicestack reference PAGE` prints today (scripts/regenerate-reference.sh
// rewrites them when the code changes).
TEST(Cli, TheReferencePagesAreWhatTheCommandsPrint) {
  for (const std::string page : {"cli", "learners", "perturbations", "regressors", "world-config"}) {
    const Process p = run("reference " + page, false);
    ASSERT_EQ(p.status, 0) << page;
    const std::string path = std::string(DICESTACK_SOURCE_DIR) + "/docs/reference/" + page + ".md";
    const std::string text = read_text(path);
    const auto history = text.find("\n## Version history\n");
    ASSERT_NE(history, std::string::npos) << path << " has no version history";
    EXPECT_TRUE(p.output == text.substr(0, history))
        << path << " differs from `dicestack reference " << page << "`: run scripts/regenerate-reference.sh";
  }
  // The listing commands print the same pages.
  EXPECT_EQ(run("learners --markdown", false).output, run("reference learners", false).output);
  EXPECT_EQ(run("regressors --markdown", false).output, run("reference regressors", false).output);
}

// The command-line page lists every subcommand and option a user can give.
TEST(Cli, TheCommandLinePageNamesEverySubcommand) {
  const std::string page = run("reference cli", false).output;
  for (const std::string sub : {"bench sim", "config", "dataset subset", "evaluate", "import robomimic", "leaderboard",
                                "play", "record", "reference", "robustness", "train"})
    EXPECT_THAT(page, HasSubstr("`dicestack " + sub + "`")) << sub;
  EXPECT_THAT(page, HasSubstr("| `--perturb` | TEXT | `none` |"));
  const Process bad = run("reference nosuch");
  EXPECT_NE(bad.status, 0);
  EXPECT_THAT(bad.output, HasSubstr("nosuch"));
}

// Every name and option of a training run is checked before its demonstrations are read: a
// bad one is named even when the demonstrations do not exist (and so before any episode).
TEST(CliInput, ABadNameOrOptionIsRefusedBeforeTheDemonstrationsAreRead) {
  const std::string base = "train --demos /nonexistent/set --out " + test::scratch_path("dicestack_cli_edge.dsm").string();
  const std::vector<std::pair<std::string, std::string>> cases{
      {" --regressor knn --learner dart --option perturb=nosuch", "option perturb: nosuch: not a perturbation level"},
      {" --regressor knn --learner dart --option perturb=medium --option estimator=none", "observation_noise cannot be labelled"},
      {" --regressor knn --learner dart --features state+x", "unknown part \"x\""},
      {" --regressor knn --learner dart --option tracker_preset=x", "\"tracker_preset\" must be one of plain, distill"},
      {" --regressor knn --set k=-1", "\"k\" must be in [1, 64]"},
      {" --regressor knn --learner dagger --option expert=oracle", "\"expert\" must be one of"},
      {" --regressor nosuch", "nosuch"}};
  for (const auto& [args, message] : cases) {
    const Process p = run_within(5, base + args);
    EXPECT_EQ(p.status, 1) << args << "\n" << p.output;
    EXPECT_THAT(p.output, HasSubstr(message)) << args;
    EXPECT_THAT(p.output, Not(HasSubstr("/nonexistent/set"))) << args << ": the demonstrations were read first";
  }
}

TEST(Cli, RolloutWritesAPng) {
  const auto png = test::scratch_path("dicestack_cli_rollout.png");
  std::filesystem::remove(png);
  const Process r = run("rollout --seed 1 --steps 20 --png " + png.string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_GT(std::filesystem::file_size(png), 1000u);
  std::filesystem::remove(png);
}

}  // namespace
}  // namespace dicestack

namespace dicestack {
namespace {

const std::string kTinyDemos = std::string(DICESTACK_SOURCE_DIR) + "/tests/datasets/data/good";

TEST(CliLearning, TrainThenEvaluateEndToEnd) {
  const auto model = test::scratch_path("dicestack_cli_knn.dsm");
  const Process t = run("train --demos " + kTinyDemos + " --regressor knn --set k=2 --split none --out " + model.string());
  ASSERT_EQ(t.status, 0) << t.output;
  const Process e = run("evaluate --model " + model.string() + " --episodes 3 --seed 2 --json --demos " + kTinyDemos);
  ASSERT_EQ(e.status, 0) << e.output;
  const auto j = nlohmann::json::parse(e.output);
  // (The two-episode set has no test episode, so no test_error.)
  for (const char* key : {"train_error", "episodes", "dice_in_cup_mean", "stacked_rate", "wall_contact_rate",
                          "realistic_success_rate", "us_per_step"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["episodes"], 3);
  std::filesystem::remove(model);
}

// A saved set replays what the sensors gave, not the estimates the policy saw: saving rollouts
// behind an estimator under sensing factors is refused before any rollout, and nothing is written.
TEST(CliLearning, SavedRolloutsBehindAnEstimatorAreRefusedUnderSensingFactors) {
  const auto model = test::scratch_path("dicestack_cli_estimated.dsm");
  const auto set = test::scratch_path("dicestack_cli_estimated_set");
  std::filesystem::remove_all(set);
  ASSERT_EQ(run("train --demos " + kTinyDemos + " --regressor knn --set k=2 --split none --out " + model.string()).status, 0);
  const std::string base = "evaluate --model " + model.string() + " --episodes 2 --save-rollouts " + set.string();
  const Process sensed = run_within(10, base + " --estimator kalman --perturb medium");
  EXPECT_EQ(sensed.status, 1) << sensed.output;
  EXPECT_THAT(sensed.output, HasSubstr("--save-rollouts with --estimator"));
  EXPECT_FALSE(std::filesystem::exists(set));
  // Without sensing factors no estimator runs, and the set is saved.
  const Process nominal = run_within(60, base + " --estimator kalman");
  EXPECT_EQ(nominal.status, 0) << nominal.output;
  EXPECT_TRUE(std::filesystem::exists(set / "meta.json"));
  std::filesystem::remove_all(set);
  std::filesystem::remove(model);
}

// A policy trained with perturb= behind the estimator runs behind it by default: evaluate and
// robustness take the model's own unless --estimator says otherwise.
TEST(CliLearning, APolicyTrainedBehindTheEstimatorIsEvaluatedBehindIt) {
  const auto model = test::scratch_path("dicestack_cli_behind.dsm");
  ASSERT_EQ(run("train --demos " + kTinyDemos + " --regressor knn --set k=2 --split none --learner dart --option expert=scripted "
                "--option episodes=2 --option successes_only=false --option perturb=medium --out " + model.string())
                .status,
            0);
  const std::string base = "evaluate --model " + model.string() + " --episodes 2 --perturb medium --json";
  const auto own = nlohmann::json::parse(run(base, false).output), asked = nlohmann::json::parse(run(base + " --estimator kalman", false).output),
             raw = nlohmann::json::parse(run(base + " --estimator none", false).output);
  EXPECT_EQ(own.value("estimator", ""), "kalman");
  EXPECT_EQ(own["dice_in_cup_mean"], asked["dice_in_cup_mean"]);
  EXPECT_EQ(own["mean_episode_length"], asked["mean_episode_length"]);
  EXPECT_FALSE(raw.contains("estimator"));
  const Process table = run("robustness --model " + model.string() + " --episodes 1 --factors observation_delay", false);
  EXPECT_THAT(table.output, HasSubstr("the kalman estimator's estimate"));
  std::filesystem::remove(model);
}

TEST(CliLearning, PaperStartsAreNamedWhereTheyAreUsedAndAnotherNameIsRefused) {
  const auto model = test::scratch_path("dicestack_cli_start.dsm");
  const auto rollouts = test::scratch_path("dicestack_cli_start_rollouts");
  std::filesystem::remove_all(rollouts);
  ASSERT_EQ(run("train --demos " + kTinyDemos + " --regressor knn --split none --out " + model.string()).status, 0);
  Process e = run("evaluate --model " + model.string() + " --episodes 2 --start paper --json --save-rollouts " +
                  rollouts.string());
  ASSERT_EQ(e.status, 0) << e.output;
  EXPECT_EQ(nlohmann::json::parse(e.output)["start"], "paper");
  const DemoSet set = read_demo_set(rollouts);
  EXPECT_EQ(start_distribution_name(set.world), "paper");
  EXPECT_THAT(set.provenance, HasSubstr("--start paper"));
  const State home = paper_start_state(set.world);
  for (const auto& ep : set.episodes) EXPECT_NEAR(ep.states[0][1], home[1], 1e-6);  // at the paper's height
  e = run("evaluate --model " + model.string() + " --episodes 2");
  EXPECT_THAT(e.output, Not(HasSubstr("paper")));
  EXPECT_FALSE(nlohmann::json::parse(run("evaluate --model " + model.string() + " --episodes 2 --json").output).contains("start"));
  for (const std::string& cmd : {"evaluate --model " + model.string(), "record --expert scripted --episodes 1 --out " +
                                                                         rollouts.string() + "x"}) {
    const Process bad = run(cmd + " --start papers");
    EXPECT_NE(bad.status, 0) << cmd;
    EXPECT_THAT(bad.output, HasSubstr("--start")) << cmd;
  }
  std::filesystem::remove(model);
  std::filesystem::remove_all(rollouts);
}

TEST(CliLearning, LeaderboardRecordingsDrawsALearningCurveFromTheDrawsDatasetSubsetWrites) {
  const auto out = test::scratch_path("dicestack_cli_curve.csv");
  const auto subset = test::scratch_path("dicestack_cli_subset");
  std::filesystem::remove(out);
  std::filesystem::remove_all(subset);
  Process p = run("leaderboard --recordings 1 --draws 2 --seed 4 --learners bc --regressors knn --episodes 2 --demos " + kTinyDemos +
                  " --format csv --out " + out.string());
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_THAT(p.output, HasSubstr("| bc | knn | 1 | 2 |"));  // the summary, printed as md
  std::ifstream in(out);
  std::string header, first;
  std::getline(in, header);
  std::getline(in, first);
  EXPECT_EQ(header.rfind("learner,regressor,recordings,draw_seed", 0), 0u);
  EXPECT_EQ(first.rfind("bc,knn,1,4,2,", 0), 0u) << first;
  p = run("dataset subset " + kTinyDemos + " --recordings 1 --seed 4 --out " + subset.string());
  ASSERT_EQ(p.status, 0) << p.output;
  const DemoSet drawn = read_demo_set(subset);
  ASSERT_EQ(drawn.episodes.size(), 1u);
  // The curve's draw 4 is the recording the subset of seed 4 holds.
  const std::size_t quote = first.find('"');
  ASSERT_NE(quote, std::string::npos) << first;
  const std::string name = first.substr(quote + 1, first.find('"', quote + 1) - quote - 1);
  EXPECT_THAT(drawn.provenance, HasSubstr("--recordings 1 --seed 4: " + name + " of "));
  p = run("leaderboard --recordings 1 --baselines cmaes --demos " + kTinyDemos);
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("--baselines is for the table"));
  p = run("leaderboard --recordings 0 --demos " + kTinyDemos);
  EXPECT_NE(p.status, 0);
  std::filesystem::remove(out);
  std::filesystem::remove_all(subset);
}

TEST(CliLearning, WithoutATestEpisodeEveryCommandReportsNoTestErrorRatherThanZero) {
  // The two-episode set leaves the episode split no test episode.
  const Process bench = run("bench regressors --demos " + kTinyDemos + " --regressors linear_svr --calls 50 --json");
  ASSERT_EQ(bench.status, 0) << bench.output;
  const auto rows = nlohmann::json::parse(bench.output);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(rows[0].contains("train_error"));
  EXPECT_FALSE(rows[0].contains("test_error")) << bench.output;
  const Process table = run("bench regressors --demos " + kTinyDemos + " --regressors linear_svr --calls 50");
  ASSERT_EQ(table.status, 0) << table.output;
  EXPECT_THAT(table.output, ::testing::ContainsRegex("linear_svr .* -\n"));
  const Process train = run("train --demos " + kTinyDemos + " --regressor linear_svr --json --out " +
                            (test::scratch_path("dicestack_cli_no_test.dsm")).string());
  ASSERT_EQ(train.status, 0) << train.output;
  EXPECT_EQ(train.output.find("test_error"), std::string::npos) << train.output;
  std::filesystem::remove(test::scratch_path("dicestack_cli_no_test.dsm"));
}

TEST(CliLearning, BadArgumentsGiveAClearMessage) {
  Process p = run("train --demos " + kTinyDemos + " --regressor rbf-svr --out /tmp/x.dsm");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("unknown regressor \"rbf-svr\"; registered:"));
  p = run("evaluate --model /nonexistent.dsm");
  EXPECT_NE(p.status, 0);
  p = run("leaderboard --demos /nonexistent-demos --regressors knn");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("not a folder of demonstrations"));
  p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners nope");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("unknown learner \"nope\""));
  p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --baselines annealing");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("unknown baseline \"annealing\""));
  // Options are parsed before any row trains: the bc row, first in line, never starts.
  p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners bc,dart --option episodes=abc");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("dart: parameter \"episodes\" expects an integer, got \"abc\""));
  EXPECT_THAT(p.output, Not(HasSubstr("training")));
  p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners bc,dart --option perturb=stormy");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("stormy"));
  EXPECT_THAT(p.output, Not(HasSubstr("training")));
  p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners bc,dart --option perturb=hard --option estimator=none");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("observation_noise cannot be labelled"));
  EXPECT_THAT(p.output, Not(HasSubstr("training")));
  p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners bc --option iterations=3");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("--option iterations=3: none of this leaderboard's learners (bc) has an option \"iterations\""));
}

TEST(CliLearning, DadTrainsWithACurveAndRefusesTheRowSplit) {
  const auto model = test::scratch_path("dicestack_cli_dad.dsm");
  const Process t = run("train --demos " + kTinyDemos + " --regressor knn --learner dad --split none --option windows=1 "
                        "--option corrector_iterations=1 --option demos=1 --json --out " + model.string(), false);
  ASSERT_EQ(t.status, 0) << t.output;
  const auto j = nlohmann::json::parse(t.output);
  std::ifstream curve(j.at("curve").get<std::string>());
  std::string header, line;
  std::getline(curve, header);
  EXPECT_EQ(header, "iteration,window,dataset_rows,deviation,stacked_rate,realistic_success_rate,dice_in_cup_mean");
  int rows = 0;
  while (std::getline(curve, line)) ++rows;
  EXPECT_EQ(rows, 4);  // the starting policy and 3 iterations of the one window
  std::filesystem::remove_all(model.string() + ".checkpoint");
  std::filesystem::remove(model.string() + ".curve.csv");
  std::filesystem::remove(model);
  const Process p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners dad --split rows");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("use --split episodes"));
}

// Rows and columns of a CSV file with a header: {rows, columns of every row (or -1 if they differ)}.
std::pair<int, int> csv_shape(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string line;
  int rows = -1, cols = 0;
  while (std::getline(in, line)) {
    const int c = static_cast<int>(std::count(line.begin(), line.end(), ',')) + 1;
    if (rows >= 0 && c != cols) cols = -1;
    if (rows < 0) cols = c;
    ++rows;
  }
  return {rows, cols};
}

TEST(CliLearning, BenchRegressorsExportsTheSplitItMeasured) {
  const auto dir = test::scratch_path("dicestack_cli_export");
  std::filesystem::remove_all(dir);
  const Process p = run("bench regressors --demos " + kTinyDemos + " --regressors linear_svr --split rows --calls 50 --json "
                        "--export " + dir.string(), false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(nlohmann::json::parse(p.output).at(0).at("name"), "linear_svr");
  const auto [train_x, cx] = csv_shape(dir / "train_x.csv");
  const auto [train_y, cy] = csv_shape(dir / "train_y.csv");
  const auto [test_x, tx] = csv_shape(dir / "test_x.csv");
  const auto [test_y, ty] = csv_shape(dir / "test_y.csv");
  EXPECT_EQ(cx, 24);
  EXPECT_EQ(tx, 24);
  EXPECT_EQ(cy, 3);
  EXPECT_EQ(ty, 3);
  EXPECT_EQ(train_x, train_y);
  EXPECT_EQ(test_x, test_y);
  EXPECT_GT(test_x, 0);
  EXPECT_EQ(test_x, (train_x + test_x + 3) / 4);  // ceil(25 %) of the rows
  std::filesystem::remove_all(dir);
}

TEST(CliBaselines, OptimiseWritesTheBestSequenceAndItsOutcome) {
  const auto out = test::scratch_path("dicestack_cli_optimise");
  std::filesystem::remove_all(out);
  const Process o = run("optimise --method cmaes --steps 5 --evaluations 40 --seed 3 --json --out " + out.string(), false);
  ASSERT_EQ(o.status, 0) << o.output;
  const auto j = nlohmann::json::parse(o.output);
  for (const char* key : {"best_cost", "evaluations", "evaluations_per_second", "dice_in_cup", "stacked", "wall_contact",
                          "realistic_success"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_LE(j["evaluations"].get<int>(), 40);
  const Process d = run("dataset validate " + out.string());
  EXPECT_EQ(d.status, 0) << d.output;
  EXPECT_TRUE(std::filesystem::exists(out / "optimise.json"));
  std::filesystem::remove_all(out);
  EXPECT_NE(run("optimise --method annealing --out " + out.string()).status, 0);
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CliBaselines, RrtWritesItsResult) {
  const auto out = test::scratch_path("dicestack_cli_rrt");
  std::filesystem::remove_all(out);
  const Process r = run("rrt --nodes 5 --extend-steps 2 --extend-iterations 2 --seed 1 --json --out " + out.string(), false);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["nodes"], 5);
  EXPECT_EQ(j["path_steps"].get<int>() % 2, 0);
  EXPECT_TRUE(std::filesystem::exists(out / "rrt.json"));
  EXPECT_TRUE(std::filesystem::exists(out / "meta.json")) << "a set, with no episode when there is no path";
  // Its own folder is replaced by the next run, path or none; so is one an older rrt left with
  // only rrt.json (no path found).
  ASSERT_EQ(run("rrt --nodes 3 --extend-steps 2 --extend-iterations 2 --seed 2 --out " + out.string()).status, 0);
  for (const auto& f : {"meta.json", "episode_0000.csv"}) std::filesystem::remove(out / f);
  const Process again = run("rrt --nodes 3 --extend-steps 2 --extend-iterations 2 --seed 2 --out " + out.string());
  EXPECT_EQ(again.status, 0) << again.output;
  EXPECT_TRUE(std::filesystem::exists(out / "meta.json"));
  std::filesystem::remove_all(out);
}

TEST(CliBaselines, ReinforceWritesTheGreedyEpisodeAndItsCurve) {
  const auto out = test::scratch_path("dicestack_cli_reinforce");
  std::filesystem::remove_all(out);
  const Process r = run("reinforce --iterations 3 --batch 2 --steps 6 --seed 1 --json --out " + out.string(), false);
  ASSERT_EQ(r.status, 0) << r.output;
  const auto j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["episodes"], 6);
  EXPECT_TRUE(j.contains("final_greedy_cost"));
  const auto saved = nlohmann::json::parse(std::ifstream(out / "reinforce.json"));
  EXPECT_EQ(saved["curve (iteration, mean return, greedy cost)"].size(), 3u);
  EXPECT_EQ(run("dataset validate " + out.string()).status, 0);
  std::filesystem::remove_all(out);
}

TEST(CliLearning, LeaderboardIsDeterministicAndEveryFormatIsWellFormed) {
  const std::string args = "leaderboard --demos " + kTinyDemos + " --regressors knn,linear_svr --learners bc --episodes 2 --seed 4 ";
  const Process a = run(args + "--format json", false), b = run(args + "--format json", false);
  ASSERT_EQ(a.status, 0) << a.output;
  const auto ja = nlohmann::json::parse(a.output), jb = nlohmann::json::parse(b.output);
  ASSERT_EQ(ja["rows"].size(), 3u);  // two regressors under bc, and playback
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(ja["rows"][i]["train_error"], jb["rows"][i]["train_error"]);
    EXPECT_EQ(ja["rows"][i]["wall_contact"], jb["rows"][i]["wall_contact"]);
    EXPECT_EQ(ja["rows"][i]["dice_in_cup_mean"], jb["rows"][i]["dice_in_cup_mean"]);
  }
  const Process csv = run(args + "--format csv", false);
  std::istringstream lines(csv.output);
  std::string line;
  std::size_t header_fields = 0, n = 0;
  while (std::getline(lines, line)) {
    const auto fields = static_cast<std::size_t>(std::count(line.begin(), line.end(), ',')) + 1;
    if (n++ == 0) header_fields = fields;
    EXPECT_EQ(fields, header_fields) << line;
  }
  EXPECT_EQ(n, 4u);
  const Process md = run(args + "--format md", false);
  EXPECT_THAT(md.output, HasSubstr("| knn | bc |"));
  EXPECT_THAT(md.output, HasSubstr("split episodes: i % 5 == 4 is test"));
  const Process tex = run(args + "--format latex", false);
  EXPECT_THAT(tex.output, HasSubstr("\\begin{tabular}"));
  EXPECT_THAT(tex.output, HasSubstr("\\end{tabular}"));
}

TEST(CliLearning, DartTrainsAHistoryModelThatEvaluateAndTheLeaderboardShow) {
  const auto model = std::filesystem::temp_directory_path() / ("dicestack_cli_dart_" + std::to_string(getpid()) + ".dsm");
  Process p = run("train --demos " + kTinyDemos + " --regressor knn --learner dart --option episodes=3 --option successes_only=false --seed 1 --out " +
                  model.string() + " --json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(nlohmann::json::parse(p.output)["features"], "state+clock+start_state");
  p = run("evaluate --model " + model.string() + " --episodes 2 --json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(nlohmann::json::parse(p.output)["features"], "state+clock+start_state");
  // --save-rollouts writes the rollouts as a set, and refuses a user's folder.
  const auto rollouts = std::filesystem::temp_directory_path() / ("dicestack_cli_rollouts_" + std::to_string(getpid()));
  const auto videos = rollouts.string() + "_videos";
  p = run("evaluate --model " + model.string() + " --episodes 2 --save-rollouts " + rollouts.string() + " --video-dir " +
          videos + " --video-format gif");
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_THAT(run("dataset info " + rollouts.string()).output, HasSubstr("episodes 2"));
  EXPECT_THAT(run("dataset info " + rollouts.string()).output,
              HasSubstr("final state, rewards and end flags (format v2): 2 of 2 episodes"));
  // One video per rollout, named as the saved episodes are.
  EXPECT_GT(std::filesystem::file_size(std::filesystem::path(videos) / "episode_0000.gif"), 1000u);
  EXPECT_GT(std::filesystem::file_size(std::filesystem::path(videos) / "episode_0001.gif"), 1000u);
  std::filesystem::remove_all(videos);
  { std::ofstream(videos) << "a file"; }
  p = run("evaluate --model " + model.string() + " --episodes 1 --video-dir " + videos);
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("--video-dir exists and is not a folder"));
  std::filesystem::remove(videos);
  std::filesystem::remove_all(rollouts);
  std::filesystem::create_directories(rollouts);
  { std::ofstream(rollouts / "notes.txt") << "mine"; }
  p = run("evaluate --model " + model.string() + " --episodes 1 --save-rollouts " + rollouts.string());
  EXPECT_EQ(p.status, 1);
  EXPECT_TRUE(std::filesystem::exists(rollouts / "notes.txt"));
  std::filesystem::remove_all(rollouts);
  p = run("train --demos " + kTinyDemos + " --regressor knn --features state+tomorrow --out " + model.string());
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("feature map \"state+tomorrow\": unknown part \"tomorrow\""));
  std::filesystem::remove(model);
  // A row per learner and map; DaD keeps to its own map in a table (its rows take minutes), so its
  // state+clock row is skipped.
  p = run("leaderboard --demos " + kTinyDemos + " --regressors linear_svr --learners bc,dad --features state,state+clock "
          "--option windows=1 --option iterations=1 --option corrector_iterations=2 --episodes 2 --format json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  const auto table = nlohmann::json::parse(p.output);
  EXPECT_EQ(table["features"], nlohmann::json({"bc state", "bc state+clock", "dad state"}));
  const auto rows = table["rows"];
  ASSERT_EQ(rows.size(), 4u);  // bc state, bc state+clock, dad state, playback
  EXPECT_EQ(rows[0]["features"], "state");
  EXPECT_EQ(rows[1]["features"], "state+clock");
  EXPECT_EQ(rows[2]["learner"], "dad");
  EXPECT_EQ(rows[2]["features"], "state");
}

TEST(CliLearning, RowSplitLeavesOutDefaultMapsThatNeedEpisodes) {
  // dart's default map reads the episode's clock and start: under --split rows its row is left
  // out (the paper's Table I protocol still runs); a map named with --features is refused.
  Process p = run("leaderboard --demos " + kTinyDemos + " --regressors linear_svr --learners bc,dart --split rows "
                  "--episodes 1 --format json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(nlohmann::json::parse(p.output)["rows"].size(), 2u);  // bc, playback
  p = run("leaderboard --demos " + kTinyDemos + " --regressors linear_svr --learners bc --features state+clock "
          "--split rows --episodes 1");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("--split rows shuffles the rows"));
}

TEST(CliLearning, RecordWithNoiseRecordsTheCleanActionsAndSaysSo) {
  const auto dir = std::filesystem::temp_directory_path() / ("dicestack_cli_noise_" + std::to_string(getpid()));
  const Process p = run("record --expert scripted --episodes 2 --noise 0.2 --out " + dir.string(), false);
  ASSERT_EQ(p.status, 0) << p.output;
  std::ifstream meta(dir / "meta.json");
  const auto j = nlohmann::json::parse(meta);
  EXPECT_THAT(j["provenance"].get<std::string>(), HasSubstr("DART noise"));
  EXPECT_EQ(run("dataset validate " + dir.string()).status, 0);
  std::filesystem::remove_all(dir);
}

TEST(CliLearning, RecordBehindTheEstimatorSaysSoAndAnEstimatorNothingReadsIsRefused) {
  const auto dir = test::scratch_path("dicestack_cli_record_estimator");
  std::filesystem::remove_all(dir);
  const Process p = run("record --expert scripted --episodes 2 --perturb medium --expert-feedback observations "
                        "--estimator kalman --out " + dir.string(), false);
  ASSERT_EQ(p.status, 0) << p.output;
  std::ifstream meta(dir / "meta.json");
  EXPECT_THAT(nlohmann::json::parse(meta)["provenance"].get<std::string>(),
              HasSubstr("--expert-feedback observations --estimator kalman"));
  std::filesystem::remove_all(dir);
  const Process bad = run("record --expert scripted --episodes 1 --estimator kalman --out " + dir.string());
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("give --expert-feedback observations"));
  EXPECT_FALSE(std::filesystem::exists(dir));
}

TEST(CliLearning, RecordInJointTorquesKeepsThemAsTheActionsAndNeedsTheArm) {
  const auto dir = test::scratch_path("dicestack_cli_record_torques");
  std::filesystem::remove_all(dir);
  const Process p = run("record --expert scripted --episodes 1 --embodiment arm --controller joint_torque --noise 0.001 --out " +
                            dir.string(), false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_THAT(file_text(dir / "episode_0000.csv"), HasSubstr(",joint0_action,"));
  EXPECT_THAT(file_text(dir / "meta.json"), HasSubstr("--controller joint_torque"));
  // Behaviour cloning learns a policy in joint torques from such a set, which holds the links.
  const auto model = (dir / "bc.dsm").string();
  const Process bc = run("train --learner bc --regressor knn --demos " + dir.string() + " --embodiment arm --controller "
                         "joint_torque --features state+links+clock/osc --split none --out " + model, false);
  ASSERT_EQ(bc.status, 0) << bc.output;
  EXPECT_TRUE(std::filesystem::exists(model));
  std::filesystem::remove_all(dir);
  // The tracker in torques skips the distill preset's refinements (about 40 min in held torques)
  // unless refine= is given: this recording would not finish within the test's time otherwise.
  const Process tracked = run("record --expert tracker --demos " + kTinyDemos + " --tracker-preset distill --tracker probes=1 "
                              "--tracker robust=1 --tracker variants=false --embodiment arm --controller joint_torque "
                              "--episodes 1 --out " + dir.string(), false);
  ASSERT_EQ(tracked.status, 0) << tracked.output;
  EXPECT_THAT(file_text(dir / "meta.json"), HasSubstr("refined only with --tracker refine=N"));
  // Which path it plays is said before the episodes, and kept with the set.
  EXPECT_THAT(tracked.output, HasSubstr("the tracker follows episode_"));
  EXPECT_THAT(tracked.output, HasSubstr(" of 2 probe trials)")) << "--tracker probes=1 as given, not raised to 32";
  EXPECT_THAT(file_text(dir / "meta.json"), HasSubstr("), ranked episode_"));
  std::filesystem::remove_all(dir);
  Process bad = run("record --expert scripted --episodes 1 --controller joint_torque --out " + dir.string());
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("give --embodiment arm"));
  EXPECT_FALSE(std::filesystem::exists(dir));
  // Perturbed, its actuation factors are drawn in the torques, and the set says so (version 5).
  const Process perturbed = run("record --expert scripted --episodes 1 --embodiment arm --controller joint_torque "
                                "--perturb medium --out " + dir.string(), false);
  ASSERT_EQ(perturbed.status, 0) << perturbed.output;
  const auto meta = nlohmann::json::parse(file_text(dir / "meta.json"));
  EXPECT_EQ(meta["version"], 5);
  EXPECT_EQ(meta["episodes"][0]["perturbation"]["joint_torque_noise_std"].size(), 4u);
  std::filesystem::remove_all(dir);
}

TEST(CliLearning, RecordThroughTheTrackerNamesItsExpertAndItsRecordings) {
  const auto dir = test::scratch_path("dicestack_cli_tracker");
  const Process p = run("record --expert tracker --demos " + kTinyDemos + " --episodes 2 --out " + dir.string(), false);
  ASSERT_EQ(p.status, 0) << p.output;
  std::ifstream meta(dir / "meta.json");
  const auto j = nlohmann::json::parse(meta);
  EXPECT_THAT(j["provenance"].get<std::string>(), HasSubstr("--expert tracker "));
  EXPECT_THAT(j["provenance"].get<std::string>(), HasSubstr("--demos " + kTinyDemos));
  EXPECT_THAT(j["provenance"].get<std::string>(), HasSubstr("recordings followed: the "));
  EXPECT_EQ(j["episodes"][0]["origin"], "expert tracker");
  EXPECT_THAT(j["provenance"].get<std::string>(), Not(HasSubstr("--retry")));
  std::filesystem::remove_all(dir);
  // Trying again after a failed attempt is part of how a set was recorded: it says so.
  ASSERT_EQ(run("record --expert tracker --demos " + kTinyDemos + " --episodes 1 --retry --out " + dir.string(), false).status, 0);
  std::ifstream retried(dir / "meta.json");
  EXPECT_THAT(nlohmann::json::parse(retried)["provenance"].get<std::string>(), HasSubstr(" --retry"));
  std::filesystem::remove_all(dir);
  // The tracker without recordings, and recordings for an expert that reads none, are refused
  // before anything is written.
  Process bad = run("record --expert tracker --episodes 1 --out " + dir.string());
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("--expert tracker follows recordings: give them with --demos"));
  bad = run("record --expert mpc --demos " + kTinyDemos + " --episodes 1 --out " + dir.string());
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("expert mpc reads none"));
  EXPECT_FALSE(std::filesystem::exists(dir));
}

// The tracker's settings go by one set of names: a preset, then NAME=VALUE on top, as the
// learners' tracker_* options and the bench name them; the set says how it was recorded.
TEST(CliLearning, RecordThroughATrackerPresetWithSettingsSaysSoAndABadSettingIsRefusedAtOnce) {
  const auto dir = test::scratch_path("dicestack_cli_tracker_preset");
  std::filesystem::remove_all(dir);
  const Process p = run("record --expert tracker --demos " + kTinyDemos +
                            " --tracker-preset distill --tracker smooth=2 --tracker probes=2 --tracker refine=0 --episodes 1 --out " + dir.string(),
                        false);
  ASSERT_EQ(p.status, 0) << p.output;
  std::ifstream meta(dir / "meta.json");
  const auto j = nlohmann::json::parse(meta);
  EXPECT_THAT(j["provenance"].get<std::string>(), HasSubstr("--tracker-preset distill --tracker smooth=2 --tracker probes=2"));
  EXPECT_THAT(j["description"].get<std::string>(), HasSubstr("--tracker-preset distill"));
  std::filesystem::remove_all(dir);
  const std::vector<std::pair<std::string, std::string>> refused{
      {"record --expert tracker --demos " + kTinyDemos + " --tracker smoth=2 --episodes 1 --out " + dir.string(),
       "tracker setting \"smoth\": unknown; settings: probes, optimise, paths"},
      {"record --expert tracker --demos " + kTinyDemos + " --tracker robust=many --episodes 1 --out " + dir.string(),
       "tracker setting robust: takes a whole number, got \"many\""},
      {"record --expert tracker --demos " + kTinyDemos + " --tracker-preset tuned --episodes 1 --out " + dir.string(),
       "--tracker-preset"},
      {"record --expert mpc --tracker smooth=2 --episodes 1 --out " + dir.string(), "expert mpc has neither"},
      {"robustness --expert scripted --tracker-preset distill --episodes 1", "--tracker-preset and --tracker set --expert tracker"}};
  for (const auto& [args, message] : refused) {
    const Process bad = run_within(5, args);
    EXPECT_NE(bad.status, 0) << args;
    EXPECT_THAT(bad.output, HasSubstr(message)) << args;
  }
  EXPECT_FALSE(std::filesystem::exists(dir));
}

TEST(CliLearning, APolicyInJointTorquesTrainsOnTheArmAndWhatItCannotRunIsRefused) {
  const auto dir = std::filesystem::temp_directory_path() / ("dicestack_cli_torque_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  nlohmann::json world = nlohmann::json::parse(run("config", false).output);
  world["episode"]["max_steps"] = 30;
  world["embodiment"] = "arm";
  std::ofstream(dir / "arm.json") << world.dump();
  const std::string arm = " --world " + (dir / "arm.json").string();
  const std::string model = (dir / "t.dsm").string();
  Process p = run("train --demos " + kTinyDemos + arm + " --controller joint_torque --regressor knn --learner dart "
                  "--option expert=tracker --option episodes=2 --option successes_only=false --option tracker_probes=1 "
                  "--option tracker_robust=1 --option tracker_variants=false --out " + model + " --json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(nlohmann::json::parse(p.output)["features"], "state+links+clock+start_state@dice+retry/osc");
  EXPECT_FALSE(nlohmann::json::parse(p.output).contains("train_error")) << "recordings hold cup actions: no score";
  p = run("evaluate --model " + model + arm + " --episodes 2 --json --save-rollouts " + (dir / "set").string(), false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(run("dataset validate " + (dir / "set").string()).status, 0) << "its rollouts: an arm's episodes in joint torques";
  p = run("dataset info " + (dir / "set").string(), false);
  EXPECT_EQ(p.status, 0) << p.output;
  EXPECT_THAT(p.output, HasSubstr("joint3_action"));
  // Its actuation rows: the delay, noise and bias in its own torques.
  p = run("robustness --model " + model + arm + " --factors action_noise,action_delay --episodes 2 --format csv", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(std::count(p.output.begin(), p.output.end(), '\n'), 1 + 6) << p.output;
  const std::vector<std::pair<std::string, std::string>> refused{
      {"evaluate --model " + model + " --episodes 1", "--embodiment arm"},
      {"evaluate --model " + model + arm + " --episodes 1 --demos " + kTinyDemos, "--demos scores a policy on recordings"},
      {"evaluate --model " + model + arm + " --episodes 1 --initial-push left", "an initial push is a cup velocity change"},
      {"train --demos " + kTinyDemos + arm + " --controller joint_torque --regressor knn --out " + model, "record --embodiment arm"},
      {"leaderboard --demos " + kTinyDemos + " --controller joint_torque --regressors knn --learners dart --episodes 1", "--embodiment arm"},
      {"leaderboard --demos " + kTinyDemos + arm + " --controller joint_torque --regressors knn --learners bc --episodes 1",
       "--learners dart:expert=tracker"},
      {"leaderboard --demos " + kTinyDemos + arm + " --controller joint_torque --regressors knn --estimator particle --episodes 1",
       "the particle filter rebuilds its worlds without the arm's links"},
      {"leaderboard --demos " + kTinyDemos + arm + " --controller joint_torque --regressors knn --baselines de --episodes 1",
       "the baselines act in the cup's actions"},
      {"leaderboard --demos " + kTinyDemos + arm + " --controller joint_torque --regressors knn --learners dart --features state "
       "--episodes 1", "answers cup actions, not the --controller joint_torque ones"}};
  for (const auto& [args, message] : refused) {
    p = run(args);
    EXPECT_EQ(p.status, 1) << args;
    EXPECT_THAT(p.output, HasSubstr(message)) << args;
  }
  // The leaderboard's rows in torques: each learner's map in them, without an error on recordings of the cup.
  p = run("leaderboard --demos " + kTinyDemos + arm + " --controller joint_torque --regressors knn --learners "
          "dart:expert=tracker:episodes=2:successes_only=false:tracker_probes=1:tracker_robust=1:tracker_variants=false "
          "--episodes 2 --format json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  const auto board = nlohmann::json::parse(p.output);
  EXPECT_EQ(board["controller"], "joint_torque");
  EXPECT_EQ(board["embodiment"], "arm");
  ASSERT_GE(board["rows"].size(), 1u);
  EXPECT_EQ(board["rows"][0]["features"], "state+links+clock+start_state@dice+retry/osc");
  EXPECT_EQ(board["rows"][0]["train_error"], -1);
  EXPECT_EQ(board["rows"][0]["episodes"], 2);
  // bc learns its row from a set recorded on the arm in torques: the evaluation's rollouts above.
  p = run("leaderboard --demos " + (dir / "set").string() + arm + " --controller joint_torque --regressors knn --learners bc "
          "--episodes 1 --seeds 6 --format json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(nlohmann::json::parse(p.output)["rows"][0]["learner"], "bc");
  EXPECT_EQ(nlohmann::json::parse(p.output)["rows"][0]["train_error"], -1) << "no error over any number of seeds";
  std::filesystem::remove_all(dir);
}

TEST(CliLearning, LeaderboardRowsCanBeLearnersWithOptions) {
  const Process p = run("leaderboard --demos " + kTinyDemos + " --regressors linear_svr "
                        "--learners bc,dart:expert=tracker:episodes=2:successes_only=false:tracker_probes=1:tracker_refine=0 "
                        "--episodes 1 --format json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  const auto rows = nlohmann::json::parse(p.output)["rows"];
  ASSERT_EQ(rows.size(), 3u);  // bc, dart through the tracker, playback
  EXPECT_EQ(rows[1]["learner"], "dart:expert=tracker:episodes=2:successes_only=false:tracker_probes=1:tracker_refine=0");
  const Process bad = run("leaderboard --demos " + kTinyDemos + " --learners dart:expert=oracle --episodes 1");
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("learner \"dart:expert=oracle\""));
}

TEST(CliBaselines, LeaderboardAddsBaselineRowsFromTheSameStarts) {
  const Process p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners bc --episodes 2 --seed 4 "
                        "--baselines de,rrt --format json", false);
  ASSERT_EQ(p.status, 0) << p.output;
  const auto rows = nlohmann::json::parse(p.output)["rows"];
  ASSERT_EQ(rows.size(), 4u);  // knn under bc, the two baselines, playback
  EXPECT_EQ(rows[1]["regressor"], "de");
  EXPECT_EQ(rows[2]["regressor"], "rrt");
  for (std::size_t i = 1; i <= 2; ++i) {
    EXPECT_EQ(rows[i]["learner"], "baseline");
    EXPECT_EQ(rows[i]["episodes"], 2);
  }
}

}  // namespace
}  // namespace dicestack

#include <opencv2/videoio.hpp>

namespace dicestack {
namespace {

TEST(CliRender, VideoFramesAndPlotOfARecordedEpisode) {
  const auto dir = test::scratch_path("dicestack_cli_render");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string episode = std::string(DICESTACK_SOURCE_DIR) + "/tests/datasets/data/good/episode_0000.csv";  // 4 steps
  const Process p = run("render --episode " + episode + " --out " + (dir / "ep.avi").string() + " --plot " +
                        (dir / "plot.png").string());
  ASSERT_EQ(p.status, 0) << p.output;
  cv::VideoCapture video((dir / "ep.avi").string());
  ASSERT_TRUE(video.isOpened());
  int frames = 0;
  for (cv::Mat f; video.read(f);) ++frames;
  EXPECT_EQ(frames, 4) << "one frame per recorded step";
  ASSERT_EQ(run("render --episode " + episode + " --out " + (dir / "ep.gif").string()).status, 0);
  int error = 0;
  GifFileType* gif = DGifOpenFileName((dir / "ep.gif").c_str(), &error);
  ASSERT_NE(gif, nullptr);
  ASSERT_EQ(DGifSlurp(gif), GIF_OK);
  EXPECT_EQ(gif->ImageCount, 4) << "one GIF frame per recorded step";
  EXPECT_EQ(gif->SWidth, 900);
  EXPECT_EQ(gif->SHeight, 700);
  DGifCloseFile(gif, &error);
  EXPECT_GT(std::filesystem::file_size(dir / "plot.png"), 5000u);
  ASSERT_EQ(run("render --episode " + episode + " --out " + (dir / "frames").string()).status, 0);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir / "frames"), std::filesystem::directory_iterator{}), 4);
  const Process bad = run("render --episode " + episode + " --out " + (dir / "x.webm").string());
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("unknown output kind"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace dicestack

namespace dicestack {
namespace {

// Outputs replace only what dicestack wrote: a user's file or folder at --out is refused and left as it was.
std::filesystem::path user_folder(const std::string& name) {
  const auto root = std::filesystem::temp_directory_path() / ("dicestack_cli_safe_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(root);
  std::filesystem::create_directories(root / "out" / "sub");
  std::ofstream(root / "out" / "notes.txt") << "mine";
  std::ofstream(root / "out" / "sub" / "notes.txt") << "mine too";
  return root;
}

void expect_untouched(const std::filesystem::path& out) {
  EXPECT_TRUE(std::filesystem::exists(out / "notes.txt"));
  EXPECT_TRUE(std::filesystem::exists(out / "sub" / "notes.txt"));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(out), std::filesystem::directory_iterator{}), 2);
}

TEST(CliSafeOutputs, EveryDemoWriterRefusesAUsersFolder) {
  const auto root = user_folder("folder");
  const std::string out = (root / "out").string();
  const std::string cupdice = std::string(DICESTACK_SOURCE_DIR) + "/data/cupdice";
  for (const std::string& cmd : {"record --expert scripted --episodes 1 --out " + out,
                                "import cupdice " + cupdice + " --out " + out,
                                "optimise --method cmaes --steps 5 --evaluations 20 --out " + out,
                                "reinforce --iterations 1 --batch 2 --steps 4 --out " + out,
                                "rrt --nodes 3 --extend-steps 2 --extend-iterations 2 --out " + out}) {
    const Process p = run(cmd);
    EXPECT_EQ(p.status, 1) << cmd << "\n" << p.output;
    EXPECT_THAT(p.output, HasSubstr(out + ": exists and is not a dicestack demonstration set (it holds notes.txt")) << cmd;
    expect_untouched(root / "out");
  }
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(root), std::filesystem::directory_iterator{}), 1)
      << "no scratch folders left";
  std::filesystem::remove_all(root);
}

TEST(CliSafeOutputs, RecordRefusesAModelFileAndRewritesItsOwnSet) {
  const auto root = user_folder("model");
  const auto model = root / "policy.dsm";
  std::ofstream(model) << R"({"format": "dicestack-model", "version": 1})" << "\npayload";
  const Process p = run("record --expert scripted --episodes 1 --out " + model.string());
  EXPECT_EQ(p.status, 1) << p.output;
  EXPECT_THAT(p.output, HasSubstr(model.string() + ": exists and is not a dicestack demonstration set"));
  EXPECT_TRUE(std::filesystem::is_regular_file(model));
  const auto set = root / "set";
  for (int i = 0; i < 2; ++i) {
    const Process r = run("record --expert scripted --episodes 1 --seed " + std::to_string(i) + " --out " + set.string());
    ASSERT_EQ(r.status, 0) << r.output;
  }
  EXPECT_EQ(run("dataset validate " + set.string()).status, 0);
  const auto optimised = root / "optimised";
  for (int i = 0; i < 2; ++i)  // a set with its optimise.json sidecar is ours too
    ASSERT_EQ(run("optimise --method cmaes --steps 5 --evaluations 20 --out " + optimised.string()).status, 0);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(optimised / "optimise.json")).at("format"), "dicestack-baseline");
  std::filesystem::remove_all(root);
}

TEST(CliSafeOutputs, TrainRefusesAUsersTextFile) {
  const auto root = user_folder("train");
  const auto notes = root / "notes.txt";
  std::ofstream(notes) << "my notes\n";
  const Process p = run("train --demos " + kTinyDemos + " --regressor knn --set k=2 --split none --out " + notes.string());
  EXPECT_EQ(p.status, 1) << p.output;
  EXPECT_THAT(p.output, HasSubstr(notes.string() + ": exists and is not a dicestack model file; refusing to replace it"));
  std::ifstream in(notes);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "my notes");
  std::filesystem::remove_all(root);
}

// The bytes of every file under `root`, by relative path.
std::map<std::string, std::string> tree_bytes(const std::filesystem::path& root) {
  std::map<std::string, std::string> out;
  for (const auto& f : std::filesystem::recursive_directory_iterator(root)) {
    if (!f.is_regular_file()) continue;
    std::ifstream in(f.path(), std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    out[std::filesystem::relative(f.path(), root).string()] = text.str();
  }
  return out;
}

TEST(CliLearning, ABadRegressorSettingIsRefusedBeforeTheLearnerRecordsAnything) {
  // A million DART episodes would take hours: only a check before any work lets this return.
  const auto model = test::scratch_path("dicestack_cli_bad_set.dsm");
  const Process p = run("train --regressor gbt --set max_depth=abc --learner dart --option episodes=1000000 --out " +
                        model.string());
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("gbt: parameter \"max_depth\" expects an integer, got \"abc\""));
  EXPECT_FALSE(std::filesystem::exists(model));
}

// Starts dicestack with `args` in the background, its output dropped; returns its pid.
pid_t start(const std::string& args) {
  const std::string cmd = "exec " + std::string(DICESTACK_EXE) + " " + args + " >/dev/null 2>&1";
  const pid_t pid = fork();
  if (pid == 0) {
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// The exit status of `pid` once it ends, or -1 if it has not ended within `seconds` (it is
// then killed) or ended by a signal.
int wait_for(pid_t pid, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int raw = 0;
  while (waitpid(pid, &raw, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > end) {
      kill(pid, SIGKILL);
      waitpid(pid, &raw, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
}

TEST(CliInterrupt, CtrlCStopsALongRunAtOnceAndLeavesTheOldOutput) {
  const auto out = test::scratch_path("dicestack_cli_interrupt");
  std::filesystem::remove_all(out);
  ASSERT_EQ(run("record --expert mpc --episodes 2 --out " + out.string()).status, 0);
  const std::string meta = file_text(out / "meta.json");
  pid_t pid = start("record --expert mpc --noise 0.1 --episodes 100000 --out " + out.string());
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  kill(pid, SIGINT);
  EXPECT_EQ(wait_for(pid, 10.0), 130);
  EXPECT_EQ(file_text(out / "meta.json"), meta) << "the set it was replacing is kept";
  for (const auto& entry : std::filesystem::directory_iterator(out.parent_path()))
    EXPECT_NE(entry.path().filename().string().rfind("." + out.filename().string(), 0), 0u) << "scratch left: " << entry.path();
  std::filesystem::remove_all(out);

  const auto model = test::scratch_path("dicestack_cli_interrupt.dsm");
  pid = start("train --regressor gbt --learner dart --option episodes=30000 --out " + model.string());
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  kill(pid, SIGINT);
  EXPECT_EQ(wait_for(pid, 10.0), 130);
  EXPECT_FALSE(std::filesystem::exists(model));
}

TEST(Cli, LearnersListEachBaseFeatureMapAndTheirTwinsOnce) {
  const Process p = run("learners", false);
  ASSERT_EQ(p.status, 0) << p.output;
  for (const auto& name : feature_map_names()) {
    if (name.find('/') == std::string::npos) {
      EXPECT_THAT(p.output, HasSubstr("  " + name + " ")) << name;
    }
  }
  EXPECT_THAT(p.output, HasSubstr("each also as NAME/velocity"));
  EXPECT_THAT(p.output, HasSubstr("NAME/position"));
  EXPECT_THAT(p.output, HasSubstr("NAME/ahead"));
  EXPECT_THAT(p.output, Not(HasSubstr("state/ahead"))) << "the twins are not listed one by one";
}

TEST(CliLearning, HugeCountsAreRefusedSayingWhatTheyWouldNeed) {
  const auto out = test::scratch_path("dicestack_cli_huge");
  Process p = run("record --expert mpc --episodes 1000000000 --out " + out.string());
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("recording: 1000000000 episodes would need up to"));
  EXPECT_THAT(p.output, HasSubstr("this machine has"));
  EXPECT_FALSE(std::filesystem::exists(out));
  const auto model = test::scratch_path("dicestack_cli_huge.dsm");
  ASSERT_EQ(run("train --demos " + kTinyDemos + " --regressor knn --split none --out " + model.string()).status, 0);
  p = run("evaluate --model " + model.string() + " --episodes 2000000000");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("evaluate: 2000000000 rollouts would need up to"));
  // Thread counts: each thread holds a world; a count beyond the bound is refused at the edge.
  for (const std::string& cmd : {"evaluate --model " + model.string() + " --episodes 2", "record --expert scripted --episodes 2 --out " + out.string(),
                                "robustness --model " + model.string() + " --episodes 2"}) {
    p = run(cmd + " --threads 100000000");
    EXPECT_NE(p.status, 0) << cmd;
    EXPECT_THAT(p.output, HasSubstr("threads is a whole number in [0, 1024]")) << cmd;
    EXPECT_THAT(p.output, Not(HasSubstr("internal error"))) << cmd;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  // The leaderboard and the robustness table refuse their rollouts' count before training or
  // any row.
  p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners bc --episodes 1000000000");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("rollouts would need up to"));
  EXPECT_THAT(p.output, Not(HasSubstr("[1/1]"))) << "refused before the first row";
  p = run("leaderboard --demos " + kTinyDemos + " --regressors knn --learners bc --episodes 2 --seeds 1000000000");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("rollouts (rows x seeds x episodes) would need up to"));
  p = run("robustness --model " + model.string() + " --episodes 1000000000");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("rollouts would need up to"));
  EXPECT_THAT(p.output, Not(HasSubstr("[1/"))) << "refused before the first row";
  std::filesystem::remove(model);
}

TEST(CliPerturb, NoneChangesNoByteAndBadPerturbationsAreRefusedBeforeAnyWork) {
  const auto model = test::scratch_path("dicestack_cli_perturb.dsm");
  const auto world = test::scratch_path("dicestack_cli_perturb_world.json");
  const auto a = test::scratch_path("dicestack_cli_perturb_a"), b = test::scratch_path("dicestack_cli_perturb_b");
  std::ofstream(world) << to_json(test::short_world(40));
  ASSERT_EQ(run("train --demos " + kTinyDemos + " --regressor knn --set k=2 --split none --out " + model.string()).status, 0);
  const std::string eval = "evaluate --model " + model.string() + " --world " + world.string() + " --episodes 2 ";
  Process p = run(eval + "--save-rollouts " + a.string());
  ASSERT_EQ(p.status, 0) << p.output;
  p = run(eval + "--perturb none --save-rollouts " + b.string());
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(tree_bytes(a), tree_bytes(b));
  std::filesystem::remove_all(b);
  p = run(eval + "--perturb hard --save-rollouts " + b.string());
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_THAT(p.output, HasSubstr("perturbed: hard"));
  EXPECT_NE(tree_bytes(a), tree_bytes(b));
  const auto meta = nlohmann::json::parse(tree_bytes(b).at("meta.json"));
  EXPECT_EQ(meta["version"], 3) << "the values drawn are saved";
  EXPECT_EQ(meta["episodes"][0]["perturbation"]["action_delay"], 6);
  EXPECT_THAT(meta["provenance"].get<std::string>(), HasSubstr("--perturb hard"));
  std::filesystem::remove_all(b);
  p = run("record --expert scripted --episodes 2 --world " + world.string() + " --perturb easy --out " + b.string());
  ASSERT_EQ(p.status, 0) << p.output;
  const auto recorded = nlohmann::json::parse(tree_bytes(b).at("meta.json"));
  EXPECT_EQ(recorded["episodes"][1]["perturbation"]["action_delay"], 1);
  EXPECT_THAT(recorded["provenance"].get<std::string>(), HasSubstr("domain randomisation"));
  std::filesystem::remove_all(b);
  p = run(eval + "--perturb extreme --save-rollouts " + b.string());
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("none, easy, medium, hard"));
  const auto file = test::scratch_path("dicestack_cli_perturb.json");
  std::ofstream(file) << R"({"format": "dicestack-perturbation", "version": 1, "action_delay": 40})";
  p = run(eval + "--perturb " + file.string() + " --save-rollouts " + b.string());
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("\"action_delay\""));
  EXPECT_FALSE(std::filesystem::exists(b)) << "refused before any work";
  std::filesystem::remove_all(a);
  std::filesystem::remove(file);
  std::filesystem::remove(world);
  std::filesystem::remove(model);
}

TEST(CliPerturb, TheLeaderboardRollsOutInPerturbedWorldsAndSaysSo) {
  const std::string args = "leaderboard --demos " + kTinyDemos + " --regressors knn --learners bc --episodes 2 --seed 4 ";
  const Process nominal = run(args + "--format json", false), none = run(args + "--format json --perturb none", false),
                hard = run(args + "--format json --perturb hard", false);
  ASSERT_EQ(hard.status, 0) << hard.output;
  const auto jn = nlohmann::json::parse(nominal.output), j0 = nlohmann::json::parse(none.output),
             jh = nlohmann::json::parse(hard.output);
  EXPECT_FALSE(j0.contains("perturb"));
  for (const char* key : {"wall_contact", "dice_in_cup_mean", "realistic_success"})
    EXPECT_EQ(jn["rows"][0][key], j0["rows"][0][key]) << key;
  EXPECT_EQ(jh["perturb"]["action_delay"], 6);
  EXPECT_THAT(run(args + "--perturb hard", false).output, HasSubstr("rollouts in perturbed worlds (hard: friction 0.6"));
  const Process bad = run(args + "--perturb sideways");
  EXPECT_EQ(bad.status, 1);
  EXPECT_THAT(bad.output, HasSubstr("none, easy, medium, hard"));
}

TEST(CliPerturb, RobustnessWritesEveryRowInEachFormatAndOnlyReplacesItsOwnTable) {
  const auto model = test::scratch_path("dicestack_cli_robust.dsm");
  const auto world = test::scratch_path("dicestack_cli_robust_world.json");
  const auto out = test::scratch_path("dicestack_cli_robust.csv");
  std::ofstream(world) << to_json(test::short_world(20));
  ASSERT_EQ(run("train --demos " + kTinyDemos + " --regressor knn --set k=2 --split none --out " + model.string()).status, 0);
  const std::string cmd = "robustness --model " + model.string() + " --world " + world.string() + " --episodes 2 ";
  Process p = run(cmd + "--format csv --out " + out.string(), false);
  ASSERT_EQ(p.status, 0) << p.output;
  std::ifstream in(out);
  std::string line;
  int lines = 0;
  while (std::getline(in, line)) ++lines;
  EXPECT_EQ(lines, 1 + 1 + 3 * static_cast<int>(perturbation_factors().size()) + 3) << "header, none, factors, all";
  EXPECT_EQ(run(cmd + "--format csv --out " + out.string()).status, 0) << "its own table is replaced";
  p = run(cmd + "--format json", false);
  ASSERT_EQ(p.status, 0);
  EXPECT_EQ(nlohmann::json::parse(p.output)["format"], "dicestack-robustness");
  std::ofstream(out) << "my notes\n";
  p = run(cmd + "--format csv --out " + out.string());
  EXPECT_EQ(p.status, 1);
  std::ifstream mine(out);
  std::getline(mine, line);
  EXPECT_EQ(line, "my notes");
  p = run("robustness --expert nobody --world " + world.string() + " --episodes 2");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("nobody"));
  EXPECT_NE(run("robustness --world " + world.string()).status, 0) << "a model or an expert";
  p = run(cmd + "--factors none,action_delay --format csv", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(std::count(p.output.begin(), p.output.end(), '\n'), 1 + 1 + 3) << p.output;
  p = run(cmd + "--factors none,wind");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("unknown factor \"wind\""));
  // An expert's sensing rows: left out while it reads the world, measured when its feedback
  // acts on the observations; a model always acts on them.
  const std::string expert = "robustness --expert scripted --world " + world.string() + " --episodes 2 --format csv ";
  p = run(expert + "--factors observation_noise");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("no row to measure"));
  p = run(expert + "--factors none,observation_noise --expert-feedback observations", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_EQ(std::count(p.output.begin(), p.output.end(), '\n'), 1 + 1 + 3) << p.output;
  EXPECT_NE(run(expert + "--expert-feedback sometimes").status, 0);
  p = run(cmd + "--expert-feedback observations");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("--expert-feedback is for --expert"));
  // An expert in joint torques: the arm's, its actuation factors drawn in torques.
  p = run(expert + "--factors none --controller joint_torque");
  EXPECT_EQ(p.status, 1);
  EXPECT_THAT(p.output, HasSubstr("give --embodiment arm"));
  p = run(expert + "--embodiment arm --factors none,action_noise --controller joint_torque", false);
  ASSERT_EQ(p.status, 0) << p.output;
  EXPECT_THAT(p.output, HasSubstr("\nnone,none,"));
  EXPECT_THAT(p.output, HasSubstr("\naction_noise,hard,"));
  std::filesystem::remove(out);
  std::filesystem::remove(world);
  std::filesystem::remove(model);
}

}  // namespace
}  // namespace dicestack
