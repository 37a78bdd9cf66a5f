#include <dicestack/regressors/params.hpp>

#include <charconv>
#include <cmath>
#include <set>
#include <sstream>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

std::string format_number(double v) {
  std::ostringstream os;
  os.precision(15);
  os << v;
  return os.str();
}

[[noreturn]] void bad(std::string_view owner, const std::string& what) {
  throw ConfigError(std::string(owner) + ": " + what);
}

Params::Value parse_value(const ParamSpec& spec, std::string_view text, std::string_view owner) {
  const std::string quoted = "\"" + std::string(text) + "\"";
  const std::string who = "parameter \"" + spec.name + "\"";
  switch (spec.type) {
    case ParamType::integer: {
      long long v = 0;
      const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
      if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size())
        bad(owner, who + " expects an integer, got " + quoted);
      if (static_cast<double>(v) < spec.min || static_cast<double>(v) > spec.max)
        bad(owner, who + " must be in [" + format_number(spec.min) + ", " + format_number(spec.max) + "], got " +
                       std::string(text));
      return v;
    }
    case ParamType::real: {
      double v = 0.0;
      const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
      if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size())
        bad(owner, who + " expects a number, got " + quoted);
      if (!std::isfinite(v)) bad(owner, who + " must be finite, got " + std::string(text));
      if (v < spec.min)
        bad(owner, who + " must be >= " + format_number(spec.min) + ", got " + std::string(text));
      if (v > spec.max)
        bad(owner, who + " must be <= " + format_number(spec.max) + ", got " + std::string(text));
      return v;
    }
    case ParamType::boolean:
      if (text == "true" || text == "1") return true;
      if (text == "false" || text == "0") return false;
      bad(owner, who + " expects true or false, got " + quoted);
    case ParamType::choice:
      for (const auto& c : spec.choices)
        if (c == text) return std::string(text);
      {
        std::string list;
        for (const auto& c : spec.choices) list += (list.empty() ? "" : ", ") + c;
        bad(owner, who + " must be one of " + list + ", got " + quoted);
      }
    case ParamType::text:
      if (text.empty()) bad(owner, who + " must not be empty");
      return std::string(text);
  }
  bad(owner, who + " has an unknown type");
}

std::string value_text(const Params::Value& v) {
  if (const auto* i = std::get_if<long long>(&v)) return std::to_string(*i);
  if (const auto* d = std::get_if<double>(&v)) return format_number(*d);
  if (const auto* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
  return std::get<std::string>(v);
}

}  // namespace

std::string_view to_string(ParamType type) {
  switch (type) {
    case ParamType::integer: return "integer";
    case ParamType::real: return "real";
    case ParamType::boolean: return "boolean";
    case ParamType::choice: return "choice";
    case ParamType::text: return "text";
  }
  return "unknown";
}

Params::Params(const std::vector<ParamSpec>& schema, const std::vector<std::string>& assignments,
               std::string_view owner) {
  for (const auto& spec : schema) values_[spec.name] = parse_value(spec, spec.default_value, owner);
  std::set<std::string, std::less<>> seen;
  for (const auto& a : assignments) {
    const auto eq = a.find('=');
    if (eq == std::string::npos || eq == 0) bad(owner, "\"" + a + "\" is not key=value");
    const std::string key = a.substr(0, eq);
    const std::string_view text = std::string_view(a).substr(eq + 1);
    const ParamSpec* spec = nullptr;
    for (const auto& s : schema)
      if (s.name == key) spec = &s;
    if (!spec) {
      std::string names;
      for (const auto& s : schema) names += (names.empty() ? "" : ", ") + s.name;
      bad(owner, "unknown parameter \"" + key + "\" (parameters: " + (names.empty() ? "none" : names) + ")");
    }
    if (!seen.insert(key).second) bad(owner, "parameter \"" + key + "\" is set twice");
    values_[key] = parse_value(*spec, text, owner);
  }
  for (const auto& spec : schema) text_.emplace_back(spec.name, value_text(values_.at(spec.name)));
}

const Params::Value& Params::get(std::string_view name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) throw std::logic_error("parameter \"" + std::string(name) + "\" is not in the schema");
  return it->second;
}

long long Params::integer(std::string_view name) const { return std::get<long long>(get(name)); }
double Params::real(std::string_view name) const { return std::get<double>(get(name)); }
bool Params::boolean(std::string_view name) const { return std::get<bool>(get(name)); }
const std::string& Params::choice(std::string_view name) const { return std::get<std::string>(get(name)); }

std::string Params::summary() const {
  std::string out;
  for (const auto& [k, v] : text_) out += (out.empty() ? "" : ", ") + k + "=" + v;
  return out;
}

}  // namespace dicestack
