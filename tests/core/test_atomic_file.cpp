#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;

TEST(AtomicFile, NothingAppearsWithoutCommit) {
  const fs::path path = fs::temp_directory_path() / "dicestack_atomic_a.txt";
  fs::remove(path);
  {
    AtomicFile f(path);
    f.stream() << "half";
    EXPECT_TRUE(fs::exists(f.temporary_path()));
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

TEST(AtomicFile, CommitReplacesTheOldFileWhole) {
  const fs::path path = fs::temp_directory_path() / "dicestack_atomic_b.txt";
  { std::ofstream(path) << "old"; }
  {
    AtomicFile f(path);
    f.stream() << "new";
    std::ifstream still(path);
    std::string text;
    still >> text;
    EXPECT_EQ(text, "old") << "the old file stays until commit";
    f.commit();
  }
  std::ifstream in(path);
  std::string text;
  in >> text;
  EXPECT_EQ(text, "new");
  fs::remove(path);
}

TEST(AtomicFile, UnwritableDirectoryIsAnInputError) {
  EXPECT_THROW(AtomicFile("/nonexistent-dir/x.txt"), InputError);
}

}  // namespace
}  // namespace dicestack
