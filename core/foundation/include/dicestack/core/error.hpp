#pragma once
// Error taxonomy shared by every dicestack library (STYLE 7). Libraries throw; apps/ turns an
// Error into "dicestack: error: <what>" and exit status 1.
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

}  // namespace dicestack
