#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include <dicestack/core/env.hpp>
#include <dicestack/version.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;

struct Process {
  int status = -1;
  std::string output;  // stdout and stderr
};

Process run(const std::string& args) {
  Process r;
  const std::string cmd = std::string(DICESTACK_EXE) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) r.output.append(buf, n);
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
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

TEST(Cli, BadWorldConfigIsReportedWithTheField) {
  const auto dir = std::filesystem::temp_directory_path();
  const auto good = dir / "dicestack_cli_world.json";
  ASSERT_EQ(run("config --out " + good.string()).status, 0);
  auto j = nlohmann::json::parse(std::ifstream(good));
  j["physics"]["substeps"] = -2;
  const auto bad = dir / "dicestack_cli_world_bad.json";
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

TEST(Cli, RolloutWritesAPng) {
  const auto png = std::filesystem::temp_directory_path() / "dicestack_cli_rollout.png";
  std::filesystem::remove(png);
  const Process r = run("rollout --seed 1 --steps 20 --png " + png.string());
  EXPECT_EQ(r.status, 0) << r.output;
  EXPECT_GT(std::filesystem::file_size(png), 1000u);
  std::filesystem::remove(png);
}

}  // namespace
}  // namespace dicestack
