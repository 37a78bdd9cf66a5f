#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/mount.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const Ownership kText = Ownership::first_line("test text file", {"old", "new", "half"});

fs::path unique_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dicestack_atomic_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(AtomicFile, NothingAppearsWithoutCommit) {
  const fs::path path = test::scratch_path("dicestack_atomic_a.txt");
  fs::remove(path);
  {
    AtomicFile f(path, kText);
    f.stream() << "half";
    EXPECT_TRUE(fs::exists(f.temporary_path()));
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path.string() + ".tmp"));
}

TEST(AtomicFile, CommitReplacesTheOldFileWhole) {
  const fs::path path = test::scratch_path("dicestack_atomic_b.txt");
  { std::ofstream(path) << "old"; }
  {
    AtomicFile f(path, kText);
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
  EXPECT_THROW(AtomicFile("/nonexistent-dir/x.txt", kText), InputError);
}

TEST(AtomicFile, AMissingFolderIsRefusedBeforeAnyWork) {
  // check_replaceable is what commands call before they train or roll out: a missing folder
  // is named there, not when the result is written minutes later.
  const fs::path dir = unique_dir("missing");
  EXPECT_EQ(test::error_of([&] { check_replaceable(dir / "nowhere" / "m.dsm", kText); }),
            (dir / "nowhere" / "m.dsm").string() + ": its folder " + (dir / "nowhere").string() +
                " does not exist (or is not a folder); create it first");
  { std::ofstream(dir / "file") << "old\n"; }
  EXPECT_THAT(test::error_of([&] { check_replaceable(dir / "file" / "m.dsm", kText); }), HasSubstr("is not a folder"));
  EXPECT_NO_THROW(check_replaceable(dir / "m.dsm", kText));
  EXPECT_NO_THROW(check_replaceable("relative-name-in-the-working-folder.dsm", kText));
  fs::remove_all(dir);
}

TEST(AtomicFile, AFileThatIsNotOursIsRefusedAndKept) {
  const fs::path dir = unique_dir("foreign");
  const fs::path path = dir / "model.dsm";
  { std::ofstream(path) << "my own notes\n"; }
  const Ownership model = Ownership::json_first_line("dicestack model file", "dicestack-model");
  const std::string message = test::error_of([&] { AtomicFile f(path, model); });
  EXPECT_THAT(message, HasSubstr(path.string() + ": exists and is not a dicestack model file; refusing to replace it"));
  EXPECT_THROW((void)AtomicFile(path, model), InputError);
  std::ifstream in(path);
  std::string text;
  std::getline(in, text);
  EXPECT_EQ(text, "my own notes");
  EXPECT_THROW((void)AtomicFile(dir, model), InputError) << "a folder is never replaced by a file";
  { std::ofstream(path) << R"({"format": "dicestack-model", "version": 1})" << "\npayload"; }
  {
    AtomicFile f(path, model);  // one of ours: replaced
    f.stream() << R"({"format": "dicestack-model"})" << '\n';
    f.commit();
  }
  EXPECT_TRUE(model.recognises(path));
  fs::remove_all(dir);
}

TEST(AtomicFile, TwoWritersOfOnePathBothCommitAndTheLastWins) {
  const fs::path dir = unique_dir("two");
  const fs::path path = dir / "out.txt";
  AtomicFile a(path, kText), b(path, kText);
  EXPECT_NE(a.temporary_path(), b.temporary_path());
  a.stream() << "old";
  b.stream() << "new";
  EXPECT_NO_THROW(a.commit());
  EXPECT_NO_THROW(b.commit());
  std::ifstream in(path);
  std::string text;
  in >> text;
  EXPECT_EQ(text, "new");
  fs::remove_all(dir);
}

TEST(AtomicFile, DeadRunsLeftoversAreRemovedLiveOnesKept) {
  const fs::path dir = unique_dir("leftovers");
  const fs::path path = dir / "out.txt";
  const fs::path dead = dir / (".out.txt.tmp-" + std::to_string(test::dead_pid()) + "-x");
  const fs::path live = dir / (".out.txt.tmp-" + std::to_string(getpid()) + "-x");
  const fs::path parent = dir / (".out.txt.tmp-" + std::to_string(getppid()) + "-x");
  const fs::path other = dir / (".other.txt.tmp-" + std::to_string(test::dead_pid()) + "-x");
  // Our own naming: a dead pid on this host is cleaned up; on another host a pid means nothing.
  const std::string ours = temporary_sibling(path, "tmp").filename().string();  // .out.txt.tmp-<pid>-h<8 hex>-...
  const std::string host = ours.substr(ours.find("-h") + 1, 9);
  const fs::path dead_here = dir / (".out.txt.tmp-" + std::to_string(test::dead_pid()) + "-" + host + "-1x2");
  const fs::path other_host = dir / (".out.txt.tmp-" + std::to_string(test::dead_pid()) + "-h00000000-1x2");
  for (const auto& p : {dead, live, parent, other, dead_here, other_host}) std::ofstream(p) << "half";
  {
    AtomicFile f(path, kText);
    f.stream() << "new";
    f.commit();
  }
  EXPECT_FALSE(fs::exists(dead_here));
  EXPECT_TRUE(fs::exists(other_host)) << "another host's scratch file: its pid says nothing here";
  EXPECT_FALSE(fs::exists(dead)) << "a killed run's temporary file of this target is cleaned up";
  EXPECT_TRUE(fs::exists(live)) << "a running writer's temporary file is never touched";
  EXPECT_TRUE(fs::exists(parent));
  EXPECT_TRUE(fs::exists(other)) << "only leftovers of this target";
  fs::remove_all(dir);
}

// A full disk (a 16 KiB tmpfs, where this machine lets the test mount one): the error names the
// path the user chose and the operating system's reason, the old output stays, nothing is left.
class FullDisk : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = unique_dir("full");
    if (::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=16k") != 0) GTEST_SKIP() << "cannot mount a tmpfs here";
    mounted_ = true;
  }
  void TearDown() override {
    if (mounted_) ::umount(dir_.c_str());
    fs::remove_all(dir_);
  }
  fs::path dir_;
  bool mounted_ = false;
};

TEST_F(FullDisk, AFileSaysNoSpaceNamingTheUsersPathAndKeepsTheOldOne) {
  const fs::path out = dir_ / "table.txt";
  std::ofstream(out) << "old\n";
  try {
    AtomicFile f(out, kText);
    f.stream() << "new\n" << std::string(64 * 1024, 'x');
    f.commit();
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(out.string() + ": write failed: No space left on device"));
    EXPECT_THAT(e.what(), ::testing::Not(HasSubstr(".tmp")));
  }
  std::ifstream in(out);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first, "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator{}), 1) << "only the old file";
}

TEST_F(FullDisk, AFolderSaysNoSpaceNamingTheFolderNotItsScratchCopy) {
  const fs::path out = dir_ / "set";
  try {
    replace_folder(
        out, [](const fs::path&) { return true; }, [](const fs::path&) {},
        [](const fs::path& tmp) {
          AtomicFile f(tmp / "episode_0003.csv", kText, AtomicFile::Leftovers::skip);
          f.stream() << std::string(64 * 1024, 'x');
          f.commit();
        });
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr((out / "episode_0003.csv").string() + ": write failed: No space left on device"));
    EXPECT_THAT(e.what(), ::testing::Not(HasSubstr(".tmp")));
  }
  EXPECT_TRUE(fs::is_empty(dir_)) << "nothing half-written left";
}

}  // namespace
}  // namespace dicestack
