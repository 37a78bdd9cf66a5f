#pragma once
// Shared by the libFuzzer harnesses (fuzz/README section of the top README). A harness feeds
// one input to one reader. The reader may accept the input or refuse it with a dicestack::Error
// (every subclass is a documented refusal) whose message names the input it was given;
// anything else is a finding: a crash, a sanitizer report, another exception (it escapes
// LLVMFuzzerTestOneInput and libFuzzer reports it), or an Error without that context (abort).
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include <dicestack/core/error.hpp>

namespace dicestack::fuzz {

/// Runs `read`; returns true if it accepted the input, false if it refused it with an Error
/// whose what() contains `context`. Aborts (a finding) on an Error without the context.
template <class F>
bool accepted(F&& read, std::string_view context) {
  try {
    read();
    return true;
  } catch (const Error& e) {
    if (std::string_view(e.what()).find(context) == std::string_view::npos) {
      std::fprintf(stderr, "dicestack fuzz: a refusal that does not name \"%.*s\": %s\n", static_cast<int>(context.size()),
                   context.data(), e.what());
      std::abort();
    }
    return false;
  }
}

/// Aborts with `what` (a finding): for properties a harness checks beyond "no crash".
[[noreturn]] inline void finding(const char* what) {
  std::fprintf(stderr, "dicestack fuzz: %s\n", what);
  std::abort();
}

}  // namespace dicestack::fuzz
