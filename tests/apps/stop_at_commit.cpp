// Test-only LD_PRELOAD library for the kill -9 tests (test_kill.cpp): dicestack stops itself
// (SIGSTOP) just before its N-th commit to the outputs under test, so the test can kill it at
// exactly that point instead of racing it. Inert unless DICESTACK_TEST_STOP_AT_COMMIT=N and
// DICESTACK_TEST_OUTPUTS=PATH[:PATH...] (absolute paths) are set.
//
// A commit is a rename that changes what a user sees at an output: a scratch file
// (".<name>.tmp-...") renamed to a path under an output with no scratch folder in it (AtomicFile),
// or an output folder moved aside to ".<name>.old-..." (the first half of replace_folder's swap).
// Files renamed inside a scratch folder, and the swap's second half, are not commits.
#include <dlfcn.h>
#include <signal.h>
#include <sys/stat.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

namespace {

std::string_view base_name(std::string_view path) {
  const auto slash = path.rfind('/');
  return slash == std::string_view::npos ? path : path.substr(slash + 1);
}

// ".<something>.<tag>-" (temporary_sibling's names).
bool is_scratch(std::string_view name, std::string_view tag) {
  if (name.size() < 2 || name[0] != '.') return false;
  const std::string marker = "." + std::string(tag) + "-";
  return name.find(marker, 1) != std::string_view::npos;
}

bool has_scratch_folder(std::string_view path) {
  for (std::size_t at = 0; at < path.size();) {
    std::size_t end = path.find('/', at);
    if (end == std::string_view::npos) end = path.size();
    const std::string_view part = path.substr(at, end - at);
    if (is_scratch(part, "tmp") || is_scratch(part, "old")) return true;
    at = end + 1;
  }
  return false;
}

bool under_an_output(std::string_view path) {
  const char* list = std::getenv("DICESTACK_TEST_OUTPUTS");
  for (std::string_view outputs = list ? list : ""; !outputs.empty();) {
    const auto colon = outputs.find(':');
    const std::string_view output = outputs.substr(0, colon);
    if (!output.empty() && path.substr(0, output.size()) == output &&
        (path.size() == output.size() || path[output.size()] == '/'))
      return true;
    outputs = colon == std::string_view::npos ? std::string_view() : outputs.substr(colon + 1);
  }
  return false;
}

bool is_commit(const char* from, const char* to) {
  struct stat st {};
  const bool file_commit = ::stat(from, &st) == 0 && S_ISREG(st.st_mode) && is_scratch(base_name(from), "tmp") &&
                           !has_scratch_folder(to) && under_an_output(to);
  const bool moving_aside = is_scratch(base_name(to), "old") && under_an_output(from);
  return file_commit || moving_aside;
}

std::atomic<int> commits{0};

}  // namespace

extern "C" int rename(const char* from, const char* to) {
  using Rename = int (*)(const char*, const char*);
  static const Rename real = reinterpret_cast<Rename>(dlsym(RTLD_NEXT, "rename"));
  const char* stop = std::getenv("DICESTACK_TEST_STOP_AT_COMMIT");
  if (stop && from && to && is_commit(from, to) && commits.fetch_add(1) + 1 == std::atoi(stop)) raise(SIGSTOP);
  return real(from, to);
}
