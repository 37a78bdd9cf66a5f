#pragma once
// Reading a file the user named, saying why it failed: every reader opens through
// here, so a missing file, a folder given for a file or a file without read permission is
// reported as "PATH: cannot open for reading: <reason>" or "PATH: read failed: <reason>", with
// the path the user gave and the operating system's words (as AtomicFile does for writes).
// A FIFO or a device is refused before it is opened (opening a FIFO waits for a writer forever;
// /dev/zero never ends), and a file is read only up to a bound, so no input hangs a run or
// exhausts its memory.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <istream>
#include <string>

namespace dicestack {

/// The most bytes read_file takes from one file unless told otherwise: far above any model or
/// set dicestack writes (a knn model of 60,000 rows is 25 MB), far below this machine's memory.
inline constexpr std::uintmax_t kMaxReadBytes = std::uintmax_t{1} << 30;

/// The bound for a settings file a person writes (a world config, a perturbation): a few hundred
/// bytes each, so a megabyte is a file given by mistake.
inline constexpr std::uintmax_t kMaxSettingsFileBytes = std::uintmax_t{1} << 20;

/// `path` opened for binary reading. Throws InputError "PATH: cannot open for reading: <reason>"
/// ("No such file or directory", "Permission denied"), or "PATH: not a regular file (a FIFO)"
/// (a socket, a character or block device), before opening it. A folder opens; reading it fails.
std::ifstream open_for_reading(const std::filesystem::path& path);

/// Call after reading `in` (from open_for_reading) to its end: throws InputError
/// "PATH: read failed: <reason>" if a read failed midway, e.g. "Is a directory" for a folder
/// (which opens, but cannot be read) or "Input/output error".
void check_read(const std::istream& in, const std::filesystem::path& path);

/// Every byte of `path`, through open_for_reading and check_read. Throws InputError, also
/// "PATH: more than N bytes (...)" for a file larger than `max_bytes`.
std::string read_file(const std::filesystem::path& path, std::uintmax_t max_bytes = kMaxReadBytes);

}  // namespace dicestack
