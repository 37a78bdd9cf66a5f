#include <dicestack/core/world_config.hpp>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>

namespace dicestack {
namespace {

using nlohmann::json;

struct Bounds {
  double lo = -HUGE_VAL;
  double hi = HUGE_VAL;
  bool lo_open = false;  // lo itself is excluded
};

constexpr Bounds kAny{};
constexpr Bounds kPositive{0.0, HUGE_VAL, true};
constexpr Bounds kNonNegative{0.0, HUGE_VAL, false};

std::string number_text(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

std::string bound_text(const Bounds& b) {
  if (b.lo > -HUGE_VAL && b.hi < HUGE_VAL)
    return "in " + std::string(b.lo_open ? "(" : "[") + number_text(b.lo) + ", " + number_text(b.hi) + "]";
  if (b.lo > -HUGE_VAL) return std::string(b.lo_open ? "> " : ">= ") + number_text(b.lo);
  return "<= " + number_text(b.hi);
}

// Visits every field of a WorldConfig with its JSON path and bounds; one list serves reading,
// writing and validation, so a new field cannot be forgotten by one of them.
template <class Config, class Visitor>
void visit_fields(Config& c, Visitor&& v) {
  v("walls.floor_y", c.walls.floor_y, kAny);
  v("walls.left_x", c.walls.left_x, kAny);
  v("walls.right_x", c.walls.right_x, kAny);
  v("walls.ceiling_y", c.walls.ceiling_y, kAny);
  v("walls.radius", c.walls.radius, kPositive);
  v("walls.friction", c.walls.friction, kNonNegative);
  v("cup.base_width", c.cup.base_width, kPositive);
  v("cup.wall_height", c.cup.wall_height, kPositive);
  v("cup.flare", c.cup.flare, kNonNegative);
  v("cup.radius", c.cup.radius, kPositive);
  v("cup.segment_mass", c.cup.segment_mass, kPositive);
  v("cup.friction", c.cup.friction, kNonNegative);
  v("cup.start_anchor", c.cup.start_anchor, kAny);
  v("cup.start_angle", c.cup.start_angle, kAny);
  v("dice.half_size", c.dice.half_size, kPositive);
  v("dice.corner_cut", c.dice.corner_cut, kNonNegative);
  v("dice.mass", c.dice.mass, kPositive);
  v("dice.friction", c.dice.friction, kNonNegative);
  v("dice.start_x", c.dice.start_x, kAny);
  v("dice.start_y", c.dice.start_y, kAny);
  v("physics.gravity", c.physics.gravity, kAny);
  v("physics.control_dt", c.physics.control_dt, Bounds{0.0, 1.0, true});
  v("physics.substeps", c.physics.substeps, Bounds{1, 1000});
  v("physics.velocity_iterations", c.physics.velocity_iterations, Bounds{1, 1000});
  v("physics.position_iterations", c.physics.position_iterations, Bounds{0, 1000});
  v("physics.allow_sleep", c.physics.allow_sleep, kAny);
  v("physics.units_per_metre", c.physics.units_per_metre, Bounds{1.0, 1000.0});
  v("physics.action_noise", c.physics.action_noise, kNonNegative);
  v("action.scale", c.action.scale, kPositive);
  v("action.limit", c.action.limit, kPositive);
  v("randomization.shift", c.randomization.shift, kNonNegative);
  v("randomization.die_jitter", c.randomization.die_jitter, kNonNegative);
  v("randomization.cup_lift", c.randomization.cup_lift, kNonNegative);
  v("randomization.cup_tilt", c.randomization.cup_tilt, Bounds{0.0, 3.2});
  v("randomization.die_quarter_turns", c.randomization.die_quarter_turns, kAny);
  v("judge.column_tolerance", c.judge.column_tolerance, kPositive);
  v("judge.gap_tolerance", c.judge.gap_tolerance, kPositive);
  v("judge.angle_tolerance", c.judge.angle_tolerance, Bounds{0.0, 0.785, true});
  v("judge.rest_speed", c.judge.rest_speed, kPositive);
  v("judge.rest_angular_speed", c.judge.rest_angular_speed, kPositive);
  v("judge.wall_contact_distance", c.judge.wall_contact_distance, kNonNegative);
  v("judge.success_hold_steps", c.judge.success_hold_steps, Bounds{1, 1e6});
  v("episode.max_steps", c.episode.max_steps, Bounds{1, 1e7});
  v("cost.gamma", c.cost.gamma, Bounds{0.0, 1.0});
  v("cost.goal_x", c.cost.goal_x, kAny);
  v("cost.sigma", c.cost.sigma, kPositive);
}

[[noreturn]] void fail(std::string_view source, std::string_view path, const std::string& what) {
  throw ConfigError("world config " + std::string(source) + ": field \"" + std::string(path) + "\" " + what);
}

void check_number(std::string_view source, std::string_view path, double v, const Bounds& b) {
  if (!std::isfinite(v)) fail(source, path, "must be finite, got " + number_text(v));
  const bool low = b.lo_open ? !(v > b.lo) : !(v >= b.lo);
  if (low || v > b.hi) fail(source, path, "must be " + bound_text(b) + ", got " + number_text(v));
}

// Checks the bounds of every field (no JSON involved).
struct RangeChecker {
  std::string_view source;
  void operator()(std::string_view p, const double& v, const Bounds& b) const { check_number(source, p, v, b); }
  void operator()(std::string_view p, const int& v, const Bounds& b) const { check_number(source, p, v, b); }
  void operator()(std::string_view, const bool&, const Bounds&) const {}
  void operator()(std::string_view p, const Vec2& v, const Bounds& b) const {
    check_number(source, std::string(p) + "[0]", v.x, b);
    check_number(source, std::string(p) + "[1]", v.y, b);
  }
  template <std::size_t N>
  void operator()(std::string_view p, const std::array<double, N>& a, const Bounds& b) const {
    for (std::size_t i = 0; i < N; ++i) check_number(source, std::string(p) + "[" + std::to_string(i) + "]", a[i], b);
  }
};

std::vector<std::string> split_path(std::string_view path) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const auto dot = path.find('.', start);
    parts.emplace_back(path.substr(start, dot - start));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
  return parts;
}

struct JsonWriter {
  json& root;
  json& slot(std::string_view path) const {
    json* node = &root;
    for (const auto& part : split_path(path)) node = &(*node)[part];
    return *node;
  }
  template <class T>
  void operator()(std::string_view p, const T& v, const Bounds&) const { slot(p) = v; }
  void operator()(std::string_view p, const Vec2& v, const Bounds&) const { slot(p) = {v.x, v.y}; }
};

struct JsonReader {
  const json& root;
  std::string_view source;
  std::set<std::string>* seen;

  const json& find(std::string_view path) const {
    const json* node = &root;
    for (const auto& part : split_path(path)) {
      if (!node->is_object() || !node->contains(part)) fail(source, path, "is missing");
      node = &(*node)[part];
    }
    seen->insert(std::string(path));
    return *node;
  }
  double number(std::string_view path, const json& j) const {
    if (!j.is_number()) fail(source, path, "must be a number, got " + j.dump());
    return j.get<double>();
  }
  void operator()(std::string_view p, double& v, const Bounds&) const { v = number(p, find(p)); }
  void operator()(std::string_view p, int& v, const Bounds&) const {
    const json& j = find(p);
    if (!j.is_number_integer()) fail(source, p, "must be an integer, got " + j.dump());
    const auto wide = j.get<long long>();
    if (wide < -(1LL << 31) || wide >= (1LL << 31)) fail(source, p, "is out of range: " + j.dump());
    v = static_cast<int>(wide);
  }
  void operator()(std::string_view p, bool& v, const Bounds&) const {
    const json& j = find(p);
    if (!j.is_boolean()) fail(source, p, "must be true or false, got " + j.dump());
    v = j.get<bool>();
  }
  template <std::size_t N>
  void read_array(std::string_view p, std::array<double, N>& a) const {
    const json& j = find(p);
    if (!j.is_array() || j.size() != N)
      fail(source, p, "must be an array of " + std::to_string(N) + " numbers, got " + j.dump());
    for (std::size_t i = 0; i < N; ++i) a[i] = number(std::string(p) + "[" + std::to_string(i) + "]", j[i]);
  }
  template <std::size_t N>
  void operator()(std::string_view p, std::array<double, N>& a, const Bounds&) const { read_array(p, a); }
  void operator()(std::string_view p, Vec2& v, const Bounds&) const {
    std::array<double, 2> a{};
    read_array(p, a);
    v = {a[0], a[1]};
  }
};

void collect_leaves(const json& j, const std::string& prefix, std::vector<std::string>& out) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items())
      collect_leaves(value, prefix.empty() ? key : prefix + "." + key, out);
  } else {
    out.push_back(prefix);
  }
}

// "field "k" value v" for the first number in `message` (quoted by nlohmann) found in `text`.
std::string overflow_context(std::string_view text, std::string_view message) {
  const auto open = message.find('\''), close = message.rfind('\'');
  if (open == std::string_view::npos || close <= open) return "a number";
  const std::string_view token = message.substr(open + 1, close - open - 1);
  const auto at = text.find(token);
  if (at == std::string_view::npos) return "number " + std::string(token);
  const auto colon = text.rfind(':', at);
  const auto key_end = colon == std::string_view::npos ? colon : text.rfind('"', colon);
  const auto key_begin = key_end == std::string_view::npos || key_end == 0 ? key_end : text.rfind('"', key_end - 1);
  if (key_begin == std::string_view::npos) return "number " + std::string(token);
  return "field \"" + std::string(text.substr(key_begin + 1, key_end - key_begin - 1)) + "\" value " + std::string(token);
}

void validate_relations(const WorldConfig& c, std::string_view source) {
  if (!(c.walls.left_x < c.walls.right_x))
    fail(source, "walls.right_x", "must be greater than walls.left_x");
  if (!(c.walls.floor_y < c.walls.ceiling_y))
    fail(source, "walls.ceiling_y", "must be greater than walls.floor_y");
  if (!(c.dice.corner_cut < c.dice.half_size))
    fail(source, "dice.corner_cut", "must be smaller than dice.half_size (" + number_text(c.dice.half_size) + "), got " +
                                        number_text(c.dice.corner_cut));
  const double speed_cap = 2.0 * c.physics.substeps / c.physics.control_dt / c.physics.units_per_metre;
  if (speed_cap <= c.action.limit[0] || speed_cap <= c.action.limit[1])
    fail(source, "physics.units_per_metre",
         "leaves Box2D's speed cap at " + number_text(speed_cap) + " m/s, not above the action limit");
}

}  // namespace

CostConfig WorldConfig::default_cost() {
  CostConfig cost;
  // Population std per state column over the 68 human recordings as imported (18,016 frames,
  // SI, cup at its centre of mass): see docs/world.md, "Cost and reward".
  cost.sigma = {1.2734, 0.7895, 0.4477, 1.2717, 0.6337, 1.8692, 4.8822, 1.0365,
                2.2418, 1.2166, 0.5323, 1.9605, 4.6541, 0.9885, 2.1754, 1.2364,
                0.6161, 2.5361, 4.6858, 1.0288, 2.4331, 4.9580, 1.1083, 1.7183};
  return cost;
}

void validate(const WorldConfig& config) {
  visit_fields(config, RangeChecker{"<value>"});
  validate_relations(config, "<value>");
}

WorldConfig world_config_from_json(std::string_view text, std::string_view source) {
  json root;
  try {
    root = parse_json_limited<json>(text, "world config " + std::string(source));
  } catch (const json::out_of_range& e) {
    // JSON has no NaN or infinity; the only way to write one is a number that overflows.
    throw ConfigError("world config " + std::string(source) + ": " + overflow_context(text, e.what()) +
                      " is not a finite number");
  } catch (const json::exception& e) {
    throw ConfigError("world config " + std::string(source) + ": not valid JSON: " + e.what());
  }
  if (!root.is_object()) throw ConfigError("world config " + std::string(source) + ": must be a JSON object");
  WorldConfig config;
  std::set<std::string> seen;
  visit_fields(config, JsonReader{root, source, &seen});
  std::vector<std::string> leaves;
  collect_leaves(root, "", leaves);
  for (const auto& leaf : leaves)
    if (!seen.contains(leaf)) fail(source, leaf, "is not a world config field");
  visit_fields(config, RangeChecker{source});
  validate_relations(config, source);
  return config;
}

std::string to_json(const WorldConfig& config) {
  json root = json::object();
  visit_fields(config, JsonWriter{root});
  return root.dump(2) + "\n";
}

std::uint64_t config_hash(const WorldConfig& config) { return fnv1a(to_json(config)); }

WorldConfig load_world_config(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open world config");
  std::ostringstream text;
  text << in.rdbuf();
  return world_config_from_json(text.str(), path.string());
}

void save_world_config(const WorldConfig& config, const std::filesystem::path& path) {
  validate(config);
  // Ours: a JSON object whose sections are all world config sections (the fields we write).
  static const json sections = json::parse(to_json(WorldConfig{}));
  const Ownership ours{"dicestack world config", [](const std::filesystem::path& p) {
                         std::ifstream in(p, std::ios::binary);
                         json j;
                         try {
                           j = parse_json_limited<json>(in, p.string());
                         } catch (const std::exception&) {
                           return false;
                         }
                         if (!j.is_object() || j.empty()) return false;
                         for (const auto& [key, value] : j.items())
                           if (!sections.contains(key)) return false;
                         return true;
                       }};
  AtomicFile file(path, ours);
  file.stream() << to_json(config);
  file.commit();
}

}  // namespace dicestack
