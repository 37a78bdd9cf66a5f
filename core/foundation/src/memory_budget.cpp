#include <dicestack/core/memory_budget.hpp>

#include <unistd.h>

#include <cstdio>
#include <string>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

std::string bytes_text(double b) {
  const char* units[] = {"B", "KB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (b >= 1024.0 && u < 5) b /= 1024.0, ++u;
  char text[32];
  std::snprintf(text, sizeof text, "%.0f %s", b, units[u]);
  return text;
}

}  // namespace

std::uint64_t physical_memory() {
  const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && size > 0 ? static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(size) : 0;
}

void require_memory(std::string_view what, std::uint64_t count, double bytes_each, std::string_view items) {
  const double have = static_cast<double>(physical_memory());
  if (have <= 0.0 || bytes_each <= 0.0) return;
  const double need = static_cast<double>(count) * bytes_each;
  if (need <= have / 2.0) return;
  throw ConfigError(std::string(what) + ": " + std::to_string(count) + " " + std::string(items) + " would need up to " +
                    bytes_text(need) + " in memory (up to " + bytes_text(bytes_each) + " each); this machine has " +
                    bytes_text(have) + ": at most " + std::to_string(static_cast<std::uint64_t>(have / 2.0 / bytes_each)) +
                    " fit");
}

}  // namespace dicestack
