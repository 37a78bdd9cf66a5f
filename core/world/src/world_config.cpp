#include <dicestack/core/hash.hpp>
#include <dicestack/core/world_config.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/geometry.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/core/read_file.hpp>

namespace dicestack {
namespace {

using nlohmann::json;

struct Bounds {
  double lo = -HUGE_VAL;
  double hi = HUGE_VAL;
  bool lo_open = false;  // lo itself is excluded
};

constexpr Bounds kAny{};
constexpr Bounds kNonNegative{0.0, HUGE_VAL, false};
// Physical ranges: wide enough for any experiment, narrow enough that Box2D (single precision,
// 10 units per metre) stays meaningful. A world 2 km wide, a 1 g die or 100 m/s^2 are refused.
constexpr Bounds kCoordinate{-1000.0, 1000.0};
constexpr Bounds kLength{0.0, 100.0, true};
constexpr Bounds kMass{1e-3, 1e3};
constexpr Bounds kFriction{0.0, 10.0};
constexpr Bounds kAcceleration{-100.0, 100.0};

constexpr const char* kFormat = "dicestack-world";
// 1: no marker, every field of WorldConfig required. 2: adds "format" and "version"; same fields.
// 3: adds "embodiment" and the "arm" section. A field added in a later version gets, in files of
// older versions, the value those versions implied (documented in docs/formats.md), never a new
// default: a file before version 3 is the floating cup.
constexpr int kVersion = 3;

// The version a field first appeared in.
int added_in(std::string_view path) { return path == "embodiment" || path.starts_with("arm.") ? 3 : 1; }

constexpr const char* kEmbodimentNames[] = {"cup", "arm"};

std::string number_text(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

// A value as the file wrote it, cut to 60 characters: messages never echo an unbounded value.
std::string excerpt(const std::string& dumped) {
  return dumped.size() <= 60 ? dumped : dumped.substr(0, 57) + "...";
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
  v("walls.floor_y", c.walls.floor_y, kCoordinate);
  v("walls.left_x", c.walls.left_x, kCoordinate);
  v("walls.right_x", c.walls.right_x, kCoordinate);
  v("walls.ceiling_y", c.walls.ceiling_y, kCoordinate);
  v("walls.radius", c.walls.radius, kLength);
  v("walls.friction", c.walls.friction, kFriction);
  v("cup.base_width", c.cup.base_width, kLength);
  v("cup.wall_height", c.cup.wall_height, kLength);
  v("cup.flare", c.cup.flare, Bounds{0.0, 100.0});
  v("cup.radius", c.cup.radius, kLength);
  v("cup.segment_mass", c.cup.segment_mass, kMass);
  v("cup.friction", c.cup.friction, kFriction);
  v("cup.start_anchor", c.cup.start_anchor, kCoordinate);
  v("cup.start_angle", c.cup.start_angle, Bounds{-10.0, 10.0});
  v("dice.half_size", c.dice.half_size, Bounds{0.01, 100.0});
  v("dice.corner_cut", c.dice.corner_cut, kNonNegative);
  v("dice.mass", c.dice.mass, kMass);
  v("dice.friction", c.dice.friction, kFriction);
  v("dice.start_x", c.dice.start_x, kCoordinate);
  v("dice.start_y", c.dice.start_y, kCoordinate);
  v("physics.gravity", c.physics.gravity, kAcceleration);
  v("physics.control_dt", c.physics.control_dt, Bounds{0.0, 1.0, true});
  v("physics.substeps", c.physics.substeps, Bounds{1, 1000});
  v("physics.velocity_iterations", c.physics.velocity_iterations, Bounds{1, 1000});
  v("physics.position_iterations", c.physics.position_iterations, Bounds{0, 1000});
  v("physics.allow_sleep", c.physics.allow_sleep, kAny);
  v("physics.units_per_metre", c.physics.units_per_metre, Bounds{1.0, 1000.0});
  v("physics.action_noise", c.physics.action_noise, Bounds{0.0, 10.0});
  v("action.scale", c.action.scale, Bounds{0.0, 1000.0, true});
  v("action.limit", c.action.limit, Bounds{0.0, 1000.0, true});
  v("randomization.shift", c.randomization.shift, Bounds{0.0, 100.0});
  v("randomization.die_jitter", c.randomization.die_jitter, Bounds{0.0, 100.0});
  v("randomization.cup_lift", c.randomization.cup_lift, Bounds{0.0, 100.0});
  v("randomization.cup_tilt", c.randomization.cup_tilt, Bounds{0.0, 3.2});
  v("randomization.die_quarter_turns", c.randomization.die_quarter_turns, kAny);
  v("judge.column_tolerance", c.judge.column_tolerance, kLength);
  v("judge.gap_tolerance", c.judge.gap_tolerance, kLength);
  v("judge.angle_tolerance", c.judge.angle_tolerance, Bounds{0.0, 0.785, true});
  v("judge.rest_speed", c.judge.rest_speed, Bounds{0.0, 1000.0, true});
  v("judge.rest_angular_speed", c.judge.rest_angular_speed, Bounds{0.0, 1000.0, true});
  v("judge.wall_contact_distance", c.judge.wall_contact_distance, Bounds{0.0, 100.0});
  v("judge.success_hold_steps", c.judge.success_hold_steps, Bounds{1, 1e6});
  v("episode.max_steps", c.episode.max_steps, Bounds{1, 1e7});
  v("cost.gamma", c.cost.gamma, Bounds{0.0, 1.0});
  v("cost.goal_x", c.cost.goal_x, kCoordinate);
  v("cost.sigma", c.cost.sigma, Bounds{0.0, 1e6, true});
  v("embodiment", c.embodiment, kAny);
  v("arm.base", c.arm.base, kCoordinate);
  v("arm.link_lengths", c.arm.link_lengths, Bounds{0.05, 100.0});
  v("arm.link_masses", c.arm.link_masses, kMass);
  v("arm.link_radius", c.arm.link_radius, Bounds{0.005, 1.0});
  v("arm.joint_lower", c.arm.joint_lower, Bounds{-100.0, 100.0});
  v("arm.joint_upper", c.arm.joint_upper, Bounds{-100.0, 100.0});
  v("arm.torque_limit", c.arm.torque_limit, Bounds{0.0, 1e7, true});
  v("arm.speed_limit", c.arm.speed_limit, Bounds{0.0, 1000.0, true});
  v("arm.posture_gain", c.arm.posture_gain, Bounds{0.0, 1000.0});
}

// What each field is, for the reference page (world_config_fields); keyed by the paths
// visit_fields walks, and a path without an entry is a defect world_config_fields reports.
struct Meaning {
  const char* path;
  const char* text;
};
constexpr Meaning kMeanings[] = {
    {"walls.floor_y", "floor centre line, m; the table surface is floor_y + radius"},
    {"walls.left_x", "left wall centre line, m"},
    {"walls.right_x", "right wall centre line, m"},
    {"walls.ceiling_y", "ceiling centre line, m"},
    {"walls.radius", "radius of the four wall segments, m"},
    {"walls.friction", "Coulomb coefficient of the walls and table (paper eq. 3)"},
    {"cup.base_width", "length of the cup's base segment, m"},
    {"cup.wall_height", "vertical rise of each side wall, m"},
    {"cup.flare", "outward offset of each wall's top, m (the cup's outward tilt)"},
    {"cup.radius", "radius of the cup's three segments, m"},
    {"cup.segment_mass", "mass of each cup segment, kg"},
    {"cup.friction", "Coulomb coefficient of the cup (paper eq. 4)"},
    {"cup.start_anchor", "left end of the base before the start rotation, m (x, y)"},
    {"cup.start_angle", "the cup's start rotation about its centre of mass, rad (pi: mouth down)"},
    {"dice.half_size", "half the side of a die's square, m"},
    {"dice.corner_cut", "length cut off each corner along both sides, m; below half_size"},
    {"dice.mass", "mass of a die, kg"},
    {"dice.friction", "Coulomb coefficient of the dice (paper eq. 2)"},
    {"dice.start_x", "the three dice's start x, m"},
    {"dice.start_y", "the dice's start height, m; they drop onto the table"},
    {"physics.gravity", "gravity, m/s^2 (x, y) (paper eq. 1)"},
    {"physics.control_dt", "one control step (one action), s"},
    {"physics.substeps", "physics steps per control step"},
    {"physics.velocity_iterations", "Box2D solver iterations per substep"},
    {"physics.position_iterations", "Box2D position correction passes per substep"},
    {"physics.allow_sleep", "let resting bodies sleep (faster, changes episodes)"},
    {"physics.units_per_metre", "Box2D's internal length scale; 10 keeps its 0.01-unit skin at 1 mm"},
    {"physics.action_noise", "std of Gaussian noise on each action, as a fraction of action.scale; 0: deterministic"},
    {"action.scale", "what an optimiser's x = 1 means per action dimension (dvx m/s, dvy m/s, dw rad/s)"},
    {"action.limit", "largest |action| accepted per dimension; larger ones are clipped"},
    {"randomization.shift", "the whole scene shifts by U(-shift, shift) in x at a random start, m"},
    {"randomization.die_jitter", "each die moves by U(-j, j) in x, m"},
    {"randomization.cup_lift", "the cup starts U(0, lift) higher, m"},
    {"randomization.cup_tilt", "the cup's start angle changes by U(-tilt, tilt), rad"},
    {"randomization.die_quarter_turns", "each die starts turned by a random multiple of 90 degrees"},
    {"judge.column_tolerance", "largest x offset between a die and the one below it in a stack, m"},
    {"judge.gap_tolerance", "largest deviation of the dice's centre spacing from one side, m"},
    {"judge.angle_tolerance", "largest deviation of a die from a multiple of 90 degrees, rad"},
    {"judge.rest_speed", "largest die speed at rest, m/s"},
    {"judge.rest_angular_speed", "largest die angular speed at rest, rad/s"},
    {"judge.wall_contact_distance", "a gap at most this wide counts as touching a wall, m"},
    {"judge.success_hold_steps", "control steps a realistic success must hold"},
    {"episode.max_steps", "the time limit, control steps"},
    {"cost.gamma", "discount of the optimisers' cost: step j weighs gamma^(T - j) (paper eq. 6)"},
    {"cost.goal_x", "x of the goal stack, m"},
    {"cost.sigma", "per state number scale of the cost's distance (the human recordings' spreads)"},
    {"embodiment", "what moves the cup: \"cup\" (the paper's floating cup: an action adds to its velocity) or \"arm\" (a planar arm holds it; docs/arm.md)"},
    {"arm.base", "the arm's shoulder joint, m (x, y)"},
    {"arm.link_lengths", "the three links' lengths, shoulder first, m"},
    {"arm.link_masses", "the three links' masses, kg"},
    {"arm.link_radius", "the links' radius (they meet the walls, the table and the ceiling), m"},
    {"arm.joint_lower", "lower limit of each joint (shoulder, elbow, second elbow, wrist), rad, relative to the previous body"},
    {"arm.joint_upper", "upper limit of each joint, rad"},
    {"arm.torque_limit", "largest torque each joint's motor gives, N m"},
    {"arm.speed_limit", "largest speed each joint is driven at, rad/s"},
    {"arm.posture_gain", "rate at which the spare degree of freedom returns to the rest posture, 1/s"},
};

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
  void operator()(std::string_view, const Embodiment&, const Bounds&) const {}
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
  void operator()(std::string_view p, const Embodiment& e, const Bounds&) const {
    slot(p) = kEmbodimentNames[static_cast<int>(e)];
  }
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
    if (!j.is_number()) fail(source, path, "must be a number, got " + excerpt(j.dump()));
    return j.get<double>();
  }
  void operator()(std::string_view p, double& v, const Bounds&) const { v = number(p, find(p)); }
  void operator()(std::string_view p, int& v, const Bounds&) const {
    const json& j = find(p);
    if (!j.is_number_integer()) fail(source, p, "must be an integer, got " + excerpt(j.dump()));
    const auto wide = j.get<long long>();
    if (wide < -(1LL << 31) || wide >= (1LL << 31)) fail(source, p, "is out of range: " + excerpt(j.dump()));
    v = static_cast<int>(wide);
  }
  void operator()(std::string_view p, bool& v, const Bounds&) const {
    const json& j = find(p);
    if (!j.is_boolean()) fail(source, p, "must be true or false, got " + excerpt(j.dump()));
    v = j.get<bool>();
  }
  void operator()(std::string_view p, Embodiment& e, const Bounds&) const {
    const json& j = find(p);
    for (int k = 0; k < 2; ++k)
      if (j.is_string() && j.get<std::string>() == kEmbodimentNames[k]) {
        e = static_cast<Embodiment>(k);
        return;
      }
    fail(source, p, "must be \"cup\" or \"arm\", got " + excerpt(j.dump()));
  }
  template <std::size_t N>
  void read_array(std::string_view p, std::array<double, N>& a) const {
    const json& j = find(p);
    if (!j.is_array() || j.size() != N)
      fail(source, p, "must be an array of " + std::to_string(N) + " numbers, got " + excerpt(j.dump()));
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

// Lists every field with its type, default, range and meaning (world_config_fields).
struct FieldLister {
  std::vector<WorldConfigField>* out;

  static std::string meaning(std::string_view path) {
    for (const auto& m : kMeanings)
      if (path == m.path) return m.text;
    throw std::logic_error("world config field \"" + std::string(path) + "\" has no meaning in kMeanings");
  }
  void add(std::string_view p, std::string type, const json& value, const Bounds& b) const {
    const bool any = b.lo == -HUGE_VAL && b.hi == HUGE_VAL;
    out->push_back({std::string(p), std::move(type), value.dump(), any ? "" : bound_text(b), meaning(p)});
  }
  void operator()(std::string_view p, const double& v, const Bounds& b) const { add(p, "number", v, b); }
  void operator()(std::string_view p, const int& v, const Bounds& b) const { add(p, "integer", v, b); }
  void operator()(std::string_view p, const bool& v, const Bounds& b) const { add(p, "boolean", v, b); }
  void operator()(std::string_view p, const Embodiment& e, const Bounds& b) const {
    add(p, "\"cup\" or \"arm\"", kEmbodimentNames[static_cast<int>(e)], b);
  }
  void operator()(std::string_view p, const Vec2& v, const Bounds& b) const {
    add(p, "2 numbers", json::array({v.x, v.y}), b);
  }
  template <std::size_t N>
  void operator()(std::string_view p, const std::array<double, N>& a, const Bounds& b) const {
    add(p, std::to_string(N) + " numbers", a, b);
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

// Where the enclosure's inside begins and ends, m.
struct Inside {
  double left, right, bottom, top;
};

// The fixed extremes of the random start: every die must lie inside the walls and apart from
// its neighbours at any shift and jitter, and the cup inside the walls at any shift, lift and
// tilt (its capsules' ends checked at 17 angles across the tilt range).
void validate_start_region(const WorldConfig& c, std::string_view source) {
  const Inside in{c.walls.left_x + c.walls.radius, c.walls.right_x - c.walls.radius, table_height(c.walls),
                  c.walls.ceiling_y - c.walls.radius};
  const auto& r = c.randomization;
  const double h = c.dice.half_size, reach = r.shift + r.die_jitter + h;
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    const double x = c.dice.start_x[i];
    const std::string field = "dice.start_x[" + std::to_string(i) + "]";
    if (x - reach < in.left || x + reach > in.right)
      fail(source, field,
           "puts die " + std::to_string(i) + " outside the walls: with half_size, randomization.shift and die_jitter it spans [" +
               number_text(x - reach) + ", " + number_text(x + reach) + "] m, the inside is [" + number_text(in.left) + ", " +
               number_text(in.right) + "]");
    for (std::size_t j = 0; j < i; ++j) {
      const double apart = std::abs(x - c.dice.start_x[j]) - 2.0 * r.die_jitter;
      if (apart < 2.0 * h - 1e-6)
        fail(source, field,
             "overlaps die " + std::to_string(j) + ": centres " + number_text(std::abs(x - c.dice.start_x[j])) +
                 " m apart, less than one side (2 * dice.half_size) plus 2 * randomization.die_jitter");
    }
  }
  if (c.dice.start_y - h < in.bottom - 1e-6 || c.dice.start_y + h > in.top)
    fail(source, "dice.start_y",
         "puts the dice outside the walls: they span [" + number_text(c.dice.start_y - h) + ", " +
             number_text(c.dice.start_y + h) + "] m, between the table at " + number_text(in.bottom) +
             " and the ceiling at " + number_text(in.top));
  const CupGeometry cup = cup_geometry(c.cup);
  const Vec2 centre{c.cup.start_anchor.x + cup.com_from_anchor.x, c.cup.start_anchor.y + cup.com_from_anchor.y};
  constexpr int kAngles = 17;
  for (int k = 0; k < kAngles; ++k) {
    const double angle = c.cup.start_angle + r.cup_tilt * (2.0 * k / (kAngles - 1) - 1.0);
    for (const auto& s : cup.segments)
      for (const Vec2 p : {s.a, s.b}) {
        const Vec2 w = to_world(centre, angle, p);
        const double lo_x = w.x - r.shift - s.radius, hi_x = w.x + r.shift + s.radius;
        const double lo_y = w.y - s.radius, hi_y = w.y + r.cup_lift + s.radius;
        if (lo_x < in.left || hi_x > in.right || lo_y < in.bottom || hi_y > in.top)
          fail(source, "cup.start_anchor",
               "puts the cup outside the walls: at start_angle " + number_text(angle) +
                   " (with randomization.shift, cup_lift and cup_tilt) a point of it reaches (" + number_text(w.x) + ", " +
                   number_text(w.y) + ") m, the inside is [" + number_text(in.left) + ", " + number_text(in.right) +
                   "] x [" + number_text(in.bottom) + ", " + number_text(in.top) + "]");
      }
  }
}

// The arm's joints are ordered, and it holds the cup at every start: the shoulder inside the
// walls, and the rest posture reaching the cup's centre at the start's extremes with every joint
// inside the walls and within its limits.
void validate_arm(const WorldConfig& c, std::string_view source) {
  const ArmConfig& arm = c.arm;
  for (std::size_t j = 0; j < 4; ++j)
    if (!(arm.joint_lower[j] < arm.joint_upper[j]))
      fail(source, "arm.joint_upper[" + std::to_string(j) + "]", "must be greater than arm.joint_lower[" + std::to_string(j) + "]");
  const Inside in{c.walls.left_x + c.walls.radius, c.walls.right_x - c.walls.radius, table_height(c.walls),
                  c.walls.ceiling_y - c.walls.radius};
  const auto inside = [&](Vec2 p) {
    return p.x - arm.link_radius > in.left && p.x + arm.link_radius < in.right && p.y - arm.link_radius > in.bottom &&
           p.y + arm.link_radius < in.top;
  };
  if (!inside(arm.base)) fail(source, "arm.base", "must lie inside the walls, clear of them by arm.link_radius");
  const CupGeometry cup = cup_geometry(c.cup);
  const Vec2 centre{c.cup.start_anchor.x + cup.com_from_anchor.x, c.cup.start_anchor.y + cup.com_from_anchor.y};
  const auto& r = c.randomization;
  for (double dx : {-r.shift, 0.0, r.shift})
    for (double dy : {0.0, r.cup_lift}) {
      const Vec2 at{centre.x + dx, centre.y + dy};
      const ArmPosture p = arm_posture(arm, at);
      if (!p.reached)
        fail(source, "arm.link_lengths",
             "cannot reach the cup's start at (" + number_text(at.x) + ", " + number_text(at.y) + ") m from arm.base");
      for (const Vec2 j : p.joints)
        if (!inside(j))
          fail(source, "arm.base", "puts a joint of the arm outside the walls holding the cup at (" + number_text(at.x) +
                                       ", " + number_text(at.y) + ") m");
    }
}

void validate_relations(const WorldConfig& c, std::string_view source) {
  if (!(c.walls.left_x + c.walls.radius < c.walls.right_x - c.walls.radius))
    fail(source, "walls.right_x", "must be greater than walls.left_x + 2 * walls.radius");
  if (!(c.walls.floor_y + c.walls.radius < c.walls.ceiling_y - c.walls.radius))
    fail(source, "walls.ceiling_y", "must be greater than walls.floor_y + 2 * walls.radius");
  if (!(c.dice.corner_cut < c.dice.half_size))
    fail(source, "dice.corner_cut", "must be smaller than dice.half_size (" + number_text(c.dice.half_size) + "), got " +
                                        number_text(c.dice.corner_cut));
  const double speed_cap = 2.0 * c.physics.substeps / c.physics.control_dt / c.physics.units_per_metre;
  if (speed_cap <= c.action.limit[0] || speed_cap <= c.action.limit[1])
    fail(source, "physics.units_per_metre",
         "leaves Box2D's speed cap at " + number_text(speed_cap) + " m/s, not above the action limit");
  validate_start_region(c, source);
  if (c.embodiment == Embodiment::arm) validate_arm(c, source);
}

// The version a config's JSON object declares: 1 without a marker, else its "version".
int declared_version(const json& root, std::string_view source) {
  const bool marked = root.contains("format"), versioned = root.contains("version");
  if (!marked && !versioned) return 1;
  if (!marked || !root["format"].is_string() || root["format"].get<std::string>() != kFormat)
    fail(source, "format", "must be \"" + std::string(kFormat) + "\" beside \"version\"");
  if (!versioned) fail(source, "version", "is missing (\"format\" is set)");
  const json& v = root["version"];
  if (!v.is_number_integer() || v.get<long long>() < 1)
    fail(source, "version", "must be a positive integer, got " + excerpt(v.dump()));
  if (v.get<long long>() > kVersion)
    throw ConfigError("world config " + std::string(source) + ": format version " + v.dump() +
                      " is newer than this dicestack reads (" + std::to_string(kVersion) + "); upgrade dicestack");
  return static_cast<int>(v.get<long long>());
}

json fields_json(const WorldConfig& config) {
  json root = json::object();
  visit_fields(config, JsonWriter{root});
  return root;
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

std::span<const double> action_limit(const WorldConfig& config, ActionKind kind) {
  if (kind == ActionKind::joint_torque) return config.arm.torque_limit;
  return config.action.limit;
}

Action clipped(const WorldConfig& config, Action action) {
  const auto limit = action_limit(config, action.kind());
  for (std::size_t k = 0; k < action.size(); ++k) action[k] = std::clamp(action[k], -limit[k], limit[k]);
  return action;
}

std::span<const double> action_scale(const WorldConfig& config, ActionKind kind) {
  if (kind == ActionKind::joint_torque) return config.arm.torque_limit;
  return config.action.scale;
}

void validate(const WorldConfig& config) {
  visit_fields(config, RangeChecker{"<value>"});
  validate_relations(config, "<value>");
}

std::vector<WorldConfigField> world_config_fields() {
  std::vector<WorldConfigField> out;
  const WorldConfig defaults;
  visit_fields(defaults, FieldLister{&out});
  if (out.size() != std::size(kMeanings)) throw std::logic_error("world config: kMeanings names a field that is gone");
  return out;
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
  // A field is read only from files of the version that added it and later; older files keep
  // the value their version implied.
  const int version = declared_version(root, source);
  root.erase("format");
  root.erase("version");
  WorldConfig config;
  std::set<std::string> seen;
  const JsonReader reader{root, source, &seen};
  visit_fields(config, [&](std::string_view p, auto& v, const Bounds& b) {
    if (added_in(p) <= version) reader(p, v, b);
  });
  std::vector<std::string> leaves;
  collect_leaves(root, "", leaves);
  for (const auto& leaf : leaves)
    if (!seen.contains(leaf)) fail(source, excerpt(leaf), "is not a world config field");
  visit_fields(config, RangeChecker{source});
  validate_relations(config, source);
  return config;
}

std::string to_json(const WorldConfig& config) {
  nlohmann::ordered_json root{{"format", kFormat}, {"version", kVersion}};  // the marker first, then the sections
  const json fields = fields_json(config);
  for (const auto& [section, values] : fields.items()) root[section] = nlohmann::ordered_json::parse(values.dump());
  return root.dump(2) + "\n";
}

std::uint64_t world_hash(const WorldConfig& config) {
  json fields = fields_json(config);
  if (config.embodiment == Embodiment::cup) {  // as before the arm existed: a cup world's identity is unchanged
    fields.erase("embodiment");
    fields.erase("arm");
  }
  return fnv1a(fields.dump(2) + "\n");
}

WorldConfig load_world_config(const std::filesystem::path& path) {
  return world_config_from_json(read_file(path, kMaxSettingsFileBytes), path.string());
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
