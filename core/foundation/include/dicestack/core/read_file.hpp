#pragma once
// Reading a file the user named, saying why it failed: every reader opens through
// here, so a missing file, a folder given for a file or a file without read permission is
// reported as "PATH: cannot open for reading: <reason>" or "PATH: read failed: <reason>", with
// the path the user gave and the operating system's words (as AtomicFile does for writes).
#include <filesystem>
#include <fstream>
#include <istream>
#include <string>

namespace dicestack {

/// `path` opened for binary reading. Throws InputError "PATH: cannot open for reading: <reason>"
/// ("No such file or directory", "Permission denied").
std::ifstream open_for_reading(const std::filesystem::path& path);

/// Call after reading `in` (from open_for_reading) to its end: throws InputError
/// "PATH: read failed: <reason>" if a read failed midway, e.g. "Is a directory" for a folder
/// (which opens, but cannot be read) or "Input/output error".
void check_read(const std::istream& in, const std::filesystem::path& path);

/// Every byte of `path`, through open_for_reading and check_read. Throws InputError.
std::string read_file(const std::filesystem::path& path);

}  // namespace dicestack
