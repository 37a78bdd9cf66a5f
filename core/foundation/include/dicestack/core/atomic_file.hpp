#pragma once
// Output files appear whole or not at all (STYLE 10): write to a temporary sibling, rename on
// commit(). And dicestack replaces only what it wrote: an existing file at an output path is
// replaced only if an Ownership test recognises it as ours (format marker or our exact header);
// anything else is refused with an InputError naming it, and nothing is removed.
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace dicestack {

/// Which existing files at an output path dicestack may replace: those `recognises` accepts.
struct Ownership {
  std::string what;  ///< what we write there, for messages: "dicestack model file"
  std::function<bool(const std::filesystem::path&)> recognises;  ///< null: any existing file may go

  /// A JSON object with "format": `format`, or (files written before the marker) one without a
  /// "format" that has every key in `legacy_keys`; an empty `legacy_keys` accepts no such file.
  static Ownership json_object(std::string what, std::string format, std::vector<std::string> legacy_keys = {});
  /// A file whose first line is a JSON object with "format": `format` (model files).
  static Ownership json_first_line(std::string what, std::string format);
  /// A file whose first line (without "\r") is one of `lines` (CSV headers, marker comments).
  static Ownership first_line(std::string what, std::vector<std::string> lines);
  /// Outputs deliberately left unguarded (rendered images): any existing file is replaced.
  static Ownership unchecked(std::string what);
};

/// Throws InputError unless nothing exists at `path` or it is a regular file `owner` recognises:
/// "PATH: exists and is not a WHAT; refusing to replace it: choose another --out or remove it yourself".
void check_replaceable(const std::filesystem::path& path, const Ownership& owner);

/// A fresh name next to `target` for a scratch file or folder:
/// ".<name>.<tag>-<pid>-h<host hash>-<unique>", unique within this process and, by a random
/// part, across processes and hosts.
std::filesystem::path temporary_sibling(const std::filesystem::path& target, std::string_view tag);

/// Leftovers of `target` named by temporary_sibling with `tag` whose writer's pid no longer
/// runs on this host (killed runs). A live run's scratch files, and another host's, are never listed.
std::vector<std::filesystem::path> dead_leftovers(const std::filesystem::path& target, std::string_view tag);

/// Writes a whole folder beside `dir` with `fill`, then swaps it in (a previous `dir` is moved
/// aside, then removed), so `dir` is never half-written. A failure (InputError, filesystem
/// errors) is thrown as an InputError naming `dir` (and paths inside it), not the scratch folder. First cleans dead runs' leftovers of
/// `dir`: their scratch folders are removed, and a folder a run moved aside and died before
/// replacing is put back when `dir` is gone and `is_ours` recognises it (it is the only copy).
/// Then `check` throws for a `dir` that is not ours; nothing is touched after a throw.
void replace_folder(const std::filesystem::path& dir, const std::function<bool(const std::filesystem::path&)>& is_ours,
                    const std::function<void(const std::filesystem::path&)>& check,
                    const std::function<void(const std::filesystem::path&)>& fill);

/// The operating system's words for `error` (an errno value): "No space left on device".
std::string os_reason(int error);

/// True when the pid names a process that exists (kill(pid, 0) does not fail with ESRCH).
bool process_is_running(long pid);

/// A file written under a temporary name and renamed over `path` by commit(). Destroying it
/// without a commit removes the temporary file, so a failure never leaves half an output.
/// Several AtomicFiles (this or other processes) may write one path at once; the last commit wins.
class AtomicFile {
 public:
  /// Whether to look for dead runs' leftovers of the path first (a scan of its folder): not
  /// inside a scratch folder this process just made, where a scan per file would cost O(n^2).
  enum class Leftovers { clean, skip };

  /// Checks `owner` (check_replaceable), removes dead runs' leftovers of `path` (unless
  /// Leftovers::skip), then opens a temporary sibling (temporary_sibling(path, "tmp")) for
  /// binary writing. Throws InputError.
  AtomicFile(std::filesystem::path path, const Ownership& owner, Leftovers leftovers = Leftovers::clean);
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
