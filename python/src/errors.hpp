#pragma once
// dicestack's exceptions as Python's, with the command line's messages: InputError and
// ConfigError become ValueError, a file or folder that does not exist FileNotFoundError, every
// other error RuntimeError. Nothing reaches the interpreter as a crash.
#include <filesystem>
#include <stdexcept>
#include <utility>

#include <dicestack/core/error.hpp>

namespace dicestack::python {

/// Raised as FileNotFoundError.
class FileNotFound : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Registers the translations with pybind11 (once, at import).
void register_error_translations();

/// Runs `read`; an InputError while `path` does not exist becomes FileNotFound with the same
/// message (the library's message names the path).
template <class Read>
decltype(auto) reading(const std::filesystem::path& path, Read&& read) {
  try {
    return std::forward<Read>(read)();
  } catch (const InputError& e) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw FileNotFound(e.what());
    throw;
  }
}

}  // namespace dicestack::python
