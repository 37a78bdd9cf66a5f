#include <dicestack/core/read_file.hpp>

#include <cerrno>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;

// What a path is when it is neither a file nor a folder, for the message; empty when it may be opened.
std::string special_kind(const fs::path& path) {
  std::error_code ec;
  switch (fs::status(path, ec).type()) {
    case fs::file_type::fifo: return "a FIFO";
    case fs::file_type::socket: return "a socket";
    case fs::file_type::character: return "a character device";
    case fs::file_type::block: return "a block device";
    case fs::file_type::unknown: return "of an unknown kind";
    default: return {};
  }
}

std::string too_large(const fs::path& path, std::uintmax_t max_bytes) {
  return path.string() + ": more than " + std::to_string(max_bytes) + " bytes (the most dicestack reads from one file)";
}

}  // namespace

// A stream keeps no reason, but the system call under it sets errno, which nothing clears before
// the stream reports the failure (the same assumption AtomicFile makes for writes).
std::ifstream open_for_reading(const std::filesystem::path& path) {
  if (const std::string kind = special_kind(path); !kind.empty())
    throw InputError(path.string() + ": not a regular file (" + kind + "); give a file");
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open for reading: " + os_reason(errno));
  return in;
}

void check_read(const std::istream& in, const std::filesystem::path& path) {
  if (in.bad()) throw InputError(path.string() + ": read failed: " + os_reason(errno));
}

std::string read_file(const std::filesystem::path& path, std::uintmax_t max_bytes) {
  std::ifstream in = open_for_reading(path);
  // The size the file system gives first (some files, such as those in /proc, say 0), then what is read.
  std::error_code ec;
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > max_bytes) throw InputError(too_large(path, max_bytes));
  std::string bytes;
  char buffer[1 << 16];
  errno = 0;
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    bytes.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (bytes.size() > max_bytes) throw InputError(too_large(path, max_bytes));
  }
  check_read(in, path);
  return bytes;
}

}  // namespace dicestack
