#include <dicestack/core/read_file.hpp>

#include <cerrno>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>

namespace dicestack {

// A stream keeps no reason, but the system call under it sets errno, which nothing clears before
// the stream reports the failure (the same assumption AtomicFile makes for writes).
std::ifstream open_for_reading(const std::filesystem::path& path) {
  errno = 0;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open for reading: " + os_reason(errno));
  return in;
}

void check_read(const std::istream& in, const std::filesystem::path& path) {
  if (in.bad()) throw InputError(path.string() + ": read failed: " + os_reason(errno));
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in = open_for_reading(path);
  std::string bytes;
  char buffer[1 << 16];
  errno = 0;
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) bytes.append(buffer, static_cast<std::size_t>(in.gcount()));
  check_read(in, path);
  return bytes;
}

}  // namespace dicestack
