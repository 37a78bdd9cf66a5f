#include <dicestack/datasets/data_paths.hpp>

#include <cstdio>
#include <cstdlib>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/cupdice_import.hpp>
#include <dicestack/datasets/demo_set.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;

std::string short_hash(std::uint64_t h) {
  char hex[9];
  std::snprintf(hex, sizeof hex, "%08llx", static_cast<unsigned long long>(h >> 32));
  return hex;
}

}  // namespace

fs::path data_dir() {
  if (const char* env = std::getenv("DICESTACK_DATA_DIR")) {
    if (!fs::is_directory(env)) throw InputError(std::string(env) + ": DICESTACK_DATA_DIR is not a folder");
    return env;
  }
  for (const fs::path& candidate : {fs::path(DICESTACK_SOURCE_DATA_DIR), fs::path(DICESTACK_INSTALL_DATA_DIR)})
    if (fs::is_directory(candidate / "cupdice")) return candidate;
  throw InputError("cannot find dicestack's data folder (looked in " DICESTACK_SOURCE_DATA_DIR " and " DICESTACK_INSTALL_DATA_DIR
                   "); set DICESTACK_DATA_DIR");
}

fs::path cache_dir() {
  fs::path dir;
  if (const char* env = std::getenv("DICESTACK_CACHE_DIR")) dir = env;
  else if (const char* xdg = std::getenv("XDG_CACHE_HOME")) dir = fs::path(xdg) / "dicestack";
  else if (const char* home = std::getenv("HOME")) dir = fs::path(home) / ".cache" / "dicestack";
  else dir = fs::temp_directory_path() / "dicestack-cache";
  fs::create_directories(dir);
  return dir;
}

fs::path human_demo_set(const WorldConfig& world) {
  const fs::path dir = cache_dir() / ("human-v2-" + short_hash(world_hash(world)));
  if (!fs::exists(dir / "meta.json")) write_demo_set(import_cupdice(data_dir() / "cupdice", world), dir);
  return dir;
}

}  // namespace dicestack
