#pragma once
// Error taxonomy shared by every dicestack library (STYLE 7). Libraries throw; apps/ turns an
// Error into "dicestack: error: <what>" and exit status 1.
#include <cstddef>
#include <stdexcept>
#include <string>

namespace dicestack {

/// Base of every error dicestack reports to a user; what() carries the full context.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad data from outside: files, states, actions, NaN. Messages start with "path:line:" for files.
class InputError : public Error {
 public:
  using Error::Error;
};

/// Bad configuration: unknown names, parameters out of range, mistyped fields.
class ConfigError : public Error {
 public:
  using Error::Error;
};

/// A plugin that cannot be loaded or was built for another ABI.
class PluginError : public Error {
 public:
  using Error::Error;
};

/// The longest word (a run without spaces) a message shows whole: longer ones are values a
/// user gave (a 1 MB option, a pasted file) and would bury the message.
inline constexpr std::size_t kLongestWordShown = 200;

/// `message` with every word longer than `longest` bytes (at least 160: a cut word keeps its
/// first 120 and last 40 bytes) cut to its start and end around "...[N characters cut]...", at
/// UTF-8 character boundaries: how the tool and the Python module show any error, whichever
/// library or parser wrote it.
std::string readable_message(const std::string& message, std::size_t longest = kLongestWordShown);

}  // namespace dicestack
