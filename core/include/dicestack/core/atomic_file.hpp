#pragma once
// Output files appear whole or not at all (STYLE 10): write to "name.tmp", rename on commit().
#include <filesystem>
#include <fstream>

namespace dicestack {

/// A file written under a temporary name and renamed over `path` by commit(). Destroying it
/// without a commit removes the temporary file, so a failure never leaves half an output.
class AtomicFile {
 public:
  /// Opens "<path>.tmp" for binary writing. Throws InputError if it cannot be created.
  explicit AtomicFile(std::filesystem::path path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return out_; }
  const std::filesystem::path& path() const { return path_; }
  const std::filesystem::path& temporary_path() const { return tmp_; }

  /// Flushes, checks for write errors and renames into place. Throws InputError on failure.
  void commit();

 private:
  std::filesystem::path path_;
  std::filesystem::path tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

}  // namespace dicestack
