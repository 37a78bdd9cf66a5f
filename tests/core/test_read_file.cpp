#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <dicestack/core/error.hpp>
#include <dicestack/core/read_file.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

TEST(ReadFile, ReadsEveryByte) {
  const fs::path path = test::scratch_path("dicestack_read_file.bin");
  std::string bytes(200000, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>(i * 7);
  { std::ofstream(path, std::ios::binary) << bytes; }
  EXPECT_EQ(read_file(path), bytes);
  fs::remove(path);
  { std::ofstream(path, std::ios::binary); }
  EXPECT_EQ(read_file(path), "") << "an empty file is not an error";
  fs::remove(path);
}

TEST(ReadFile, AMissingFileNamesThePathAndTheReason) {
  const fs::path path = test::scratch_path("dicestack_read_missing.json");
  fs::remove(path);
  EXPECT_EQ(test::error_of([&] { read_file(path); }), path.string() + ": cannot open for reading: No such file or directory");
  EXPECT_EQ(test::error_of([&] { open_for_reading(path); }),
            path.string() + ": cannot open for reading: No such file or directory");
  EXPECT_THROW(read_file(path), InputError);
}

TEST(ReadFile, AFolderOpensButItsReadFailsSayingSo) {
  const fs::path dir = test::scratch_path("dicestack_read_folder");
  fs::create_directories(dir);
  EXPECT_EQ(test::error_of([&] { read_file(dir); }), dir.string() + ": read failed: Is a directory");
  // A line-by-line reader: the loop ends at the failure, check_read says why.
  std::ifstream in = open_for_reading(dir);
  std::string line;
  while (std::getline(in, line)) {
  }
  EXPECT_EQ(test::error_of([&] { check_read(in, dir); }), dir.string() + ": read failed: Is a directory");
  fs::remove_all(dir);
}

TEST(ReadFile, AFileWithoutReadPermissionSaysPermissionDenied) {
  const fs::path path = test::scratch_path("dicestack_read_denied.json");
  { std::ofstream(path) << "{}"; }
  fs::permissions(path, fs::perms::none);
  const auto error = test::unprivileged([&] { return test::error_of([&] { read_file(path); }); });
  fs::remove(path);
  if (!error) GTEST_SKIP() << "cannot drop root's privileges here";
  EXPECT_EQ(*error, path.string() + ": cannot open for reading: Permission denied");
}

TEST(ReadFile, AReadThatFailsMidwayGivesTheSystemsReason) {
  // /proc/self/mem opens, but reading at offset 0 (never mapped) fails with EIO.
  const std::string error = test::error_of([] { read_file("/proc/self/mem"); });
  if (error.find("cannot open for reading") != std::string::npos) GTEST_SKIP() << error;
  EXPECT_EQ(error, "/proc/self/mem: read failed: Input/output error");
}

TEST(ReadFile, AFifoOrADeviceIsRefusedBeforeItIsOpened) {
  // Opening a FIFO with no writer waits forever, and /dev/zero never ends: both refused at once.
  const fs::path fifo = test::scratch_path("dicestack_read_fifo");
  fs::remove(fifo);
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_EQ(test::error_of([&] { read_file(fifo); }), fifo.string() + ": not a regular file (a FIFO); give a file");
  EXPECT_EQ(test::error_of([&] { open_for_reading(fifo); }), fifo.string() + ": not a regular file (a FIFO); give a file");
  fs::remove(fifo);
  EXPECT_EQ(test::error_of([] { read_file("/dev/zero"); }), "/dev/zero: not a regular file (a character device); give a file");
  EXPECT_THROW(read_file("/dev/null"), InputError);
}

TEST(ReadFile, AFileLargerThanItsBoundIsRefusedBeforeItIsRead) {
  const fs::path path = test::scratch_path("dicestack_read_bound.json");
  { std::ofstream(path, std::ios::binary) << std::string(100, 'x'); }
  EXPECT_EQ(read_file(path, 100).size(), 100u);
  EXPECT_EQ(test::error_of([&] { read_file(path, 99); }),
            path.string() + ": more than 99 bytes (the most dicestack reads from one file)");
  fs::remove(path);
  // A file whose size the file system does not know (0 in /proc) is bounded as it is read.
  EXPECT_THAT(test::error_of([] { read_file("/proc/self/maps", 10); }), HasSubstr(": more than 10 bytes"));
}

}  // namespace
}  // namespace dicestack
