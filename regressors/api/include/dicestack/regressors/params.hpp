#pragma once
// Regressor parameters: a schema (name, type, default, range, help) and validated values.
// `--set key=value` goes through the schema; unknown keys and bad values are errors (STYLE 6).
#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace dicestack {

/// text: any non-empty value, checked by its owner (e.g. a perturbation level or file).
enum class ParamType { integer, real, boolean, choice, text };

/// One parameter a regressor accepts.
struct ParamSpec {
  std::string name;
  ParamType type = ParamType::real;
  std::string default_value;  ///< as it would be written after "--set name="
  double min = -1e300;        ///< inclusive bounds for integer and real parameters
  double max = 1e300;
  std::string help;
  std::vector<std::string> choices;  ///< for ParamType::choice
};

/// "integer", "real", "boolean", "choice" or "text".
std::string_view to_string(ParamType type);

/// Validated parameter values, one per schema entry.
class Params {
 public:
  using Value = std::variant<long long, double, bool, std::string>;

  Params() = default;
  /// The schema's defaults overridden by `assignments` ("key=value"). `owner` names the
  /// regressor in messages. Throws ConfigError for an unknown key, a malformed assignment,
  /// a value of the wrong type or out of range.
  Params(const std::vector<ParamSpec>& schema, const std::vector<std::string>& assignments, std::string_view owner);

  long long integer(std::string_view name) const;
  double real(std::string_view name) const;
  bool boolean(std::string_view name) const;
  const std::string& choice(std::string_view name) const;  ///< a choice or text parameter

  /// name -> value as text, in schema order (for model files and reports).
  const std::vector<std::pair<std::string, std::string>>& as_text() const { return text_; }
  /// "k=3, metric=l2"
  std::string summary() const;

 private:
  const Value& get(std::string_view name) const;
  std::map<std::string, Value, std::less<>> values_;
  std::vector<std::pair<std::string, std::string>> text_;
};

}  // namespace dicestack
