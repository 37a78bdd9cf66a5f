// robomimic and Minari HDF5 together: the human recordings through both, episodes without
// transitions named, a user's files never replaced (one format: test_robomimic, test_minari).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <dicestack/datasets/cupdice_import.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/replay.hpp>
#include <dicestack/interop/interop.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/interop.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::expect_same;
using test::kSource;
using test::scratch;
using test::small_set;
using test::through_folder;

TEST(Interop, TheHumanRecordingsExportAndReimport) {
  const DemoSet set = through_folder(import_cupdice(kSource / "data" / "cupdice", WorldConfig{}), "human");
  ASSERT_EQ(set.episodes.size(), 68u);
  const fs::path file = scratch("human.hdf5"), dir = scratch("human_minari");
  export_robomimic(set, file);
  expect_same(set, import_robomimic(file));
  export_minari(set, dir, default_minari_dataset_id(dir));
  expect_same(set, import_minari(dir));
}

TEST(Interop, EpisodesWithoutTransitionsAreNamed) {
  DemoSet set = read_demo_set(kSource / "tests" / "datasets" / "data" / "good");
  EXPECT_THAT(recover_transitions(set.episodes, set.world), (std::vector<std::string>{"episode_0000", "episode_0001"}));
  const auto message = test::error_of([&] { export_robomimic(set, scratch("none.hdf5")); });
  EXPECT_THAT(message, HasSubstr("2 of 2 episodes have no final state"));
  EXPECT_THAT(message, HasSubstr("episode_0000, episode_0001"));
  EXPECT_FALSE(fs::exists(scratch("none.hdf5")));
}

TEST(Interop, AUsersFilesAreNeverReplaced) {
  const DemoSet set = through_folder(small_set(), "owner");
  const fs::path file = scratch("user.hdf5");
  std::ofstream(file) << "a user's notes\n";
  EXPECT_THAT(test::error_of([&] { export_robomimic(set, file); }), HasSubstr("exists and is not a dicestack robomimic export"));
  const fs::path dir = scratch("user_folder");
  fs::create_directories(dir / "data");
  std::ofstream(dir / "data" / "notes.txt") << "mine\n";
  EXPECT_THAT(test::error_of([&] { export_minari(set, dir, "dicestack/x-v0"); }),
              HasSubstr("exists and is not a dicestack Minari export (it holds data/notes.txt)"));
  EXPECT_TRUE(fs::exists(dir / "data" / "notes.txt"));
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "a user's notes");
}

}  // namespace
}  // namespace dicestack
