#include <dicestack/core/perturbation.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <span>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/core/read_file.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {
namespace {

using json = nlohmann::json;

constexpr const char* kPerturbationFormat = "dicestack-perturbation";
constexpr int kPerturbationVersion = 2;  // 2: "delays_drawn"
constexpr std::uint64_t kPerturbStream = 0x70657274ULL;  // "pert": a stream of its own per episode
constexpr std::uint64_t kDelayStream = 0x64656c61ULL;    // "dela": drawn delays, apart so the rest stays as in version 1
constexpr const char* kDelaysDrawn = "delays_drawn";

// The level table (docs/robustness.md). Index 0 none, 1 easy, 2 medium, 3 hard. Anchors:
// robosuite (friction +-10 %, mass +-2 %), Isaac Lab's cube (friction x[0.7, 1.3], mass
// x[0.5, 1.5], gravity +N(0, 0.4), action noise 0.05 with bias 0.015), RWRL (delays 3 / 6 / 9).
struct Row {
  const char* name;
  double levels[4];
};
constexpr Row kTable[] = {
    {"friction", {0, 0.1, 0.3, 0.6}},
    {"dice_mass", {0, 0.1, 0.5, 0.8}},
    {"cup_mass", {0, 0.1, 0.3, 0.6}},
    {"gravity", {0, 0.1, 0.4, 1.0}},
    {"action_noise", {0, 0.02, 0.05, 0.2}},  // its bias: a third of it (Isaac Lab's 0.05 / 0.015)
    {"action_delay", {0, 1, 3, 6}},
    {"observation_noise", {0, 0.01, 0.05, 0.2}},
    {"observation_delay", {0, 1, 3, 6}},
    {"start", {0, 0.25, 0.5, 1.0}},
};

void set(Perturbation& p, std::string_view factor, double v) {
  if (factor == "friction") p.friction = v;
  else if (factor == "dice_mass") p.dice_mass = v;
  else if (factor == "cup_mass") p.cup_mass = v;
  else if (factor == "gravity") p.gravity = v;
  else if (factor == "action_noise") p.action_noise = v, p.action_bias = v * 0.3;
  else if (factor == "action_delay") p.action_delay = static_cast<int>(v);
  else if (factor == "observation_noise") p.observation_noise = v;
  else if (factor == "observation_delay") p.observation_delay = static_cast<int>(v);
  else if (factor == "start") p.start_widening = v;
}

std::size_t level_index(std::string_view level) {
  const auto& levels = perturbation_levels();
  for (std::size_t i = 0; i < levels.size(); ++i)
    if (levels[i] == level) return i;
  throw ConfigError("perturbation: level \"" + std::string(level) + "\" is not one of none, easy, medium, hard");
}

std::string list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// The JSON keys and their fields, in file order, with the largest value each takes (0 is the
// least of every one) and what it does: one table serves reading, writing, checking and the
// reference page.
struct Key {
  const char* name;
  double Perturbation::*real;
  int Perturbation::*whole;
  double hi;         // largest value; a delay must also leave the episode a step to act
  bool hi_open;      // hi itself is refused
  const char* unit;  // after the range in messages, e.g. " m/s^2"
  const char* why;   // why the bound, for messages ("" when plain)
  const char* meaning;
};
constexpr Key kKeys[] = {
    {"friction", &Perturbation::friction, nullptr, 1, true, "", "friction would turn negative",
     "dice, cup and walls/table friction each x U(1 - a, 1 + a), drawn apart"},
    {"dice_mass", &Perturbation::dice_mass, nullptr, 1, true, "", "a mass would turn non-positive",
     "dice mass x U(1 - a, 1 + a)"},
    {"cup_mass", &Perturbation::cup_mass, nullptr, 1, true, "", "a mass would turn non-positive",
     "cup segment mass x U(1 - a, 1 + a)"},
    {"gravity", &Perturbation::gravity, nullptr, 2, false, " m/s^2", "", "gravity's y + N(0, sigma), m/s^2"},
    {"action_noise", &Perturbation::action_noise, nullptr, 10, false, "", "",
     "every executed action + N(0, s) each step, s a fraction of action.scale (of the arm's torque limits for joint torques)"},
    {"action_bias", &Perturbation::action_bias, nullptr, 10, false, "", "",
     "every executed action + a bias drawn once per episode from N(0, b), b a fraction of action.scale (of the torque limits for joint torques)"},
    {"action_delay", nullptr, &Perturbation::action_delay, kMaxActionDelay, false, "", "",
     "what the policy chooses runs this many control steps later (nothing runs before)"},
    {"observation_noise", &Perturbation::observation_noise, nullptr, 10, false, "", "",
     "the policy sees each state number + N(0, f x its spread) (spreads: the built-in set's standard deviations)"},
    {"observation_delay", nullptr, &Perturbation::observation_delay, kMaxActionDelay, false, "", "",
     "the policy sees the state of this many control steps ago (the start before then)"},
    {"start_widening", &Perturbation::start_widening, nullptr, 3, false, "", "",
     "the start's scene shift, cup lift and cup tilt ranges x (1 + w)"},
};

// "in [0, 1) (friction would turn negative)": a key's range as messages and the reference say it.
std::string range_text(const Key& k, double hi) {
  std::ostringstream text;
  text << "in [0, " << hi << (k.hi_open ? ")" : "]") << k.unit;
  if (*k.why) text << " (" << k.why << ")";
  return text.str();
}

}  // namespace

const std::vector<std::string>& perturbation_factors() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& r : kTable) out.emplace_back(r.name);
    return out;
  }();
  return names;
}

const std::vector<std::string>& perturbation_levels() {
  static const std::vector<std::string> names{"none", "easy", "medium", "hard"};
  return names;
}

Perturbation perturbation_level(std::string_view level) {
  const std::size_t i = level_index(level);
  Perturbation p;
  for (const auto& r : kTable) set(p, r.name, r.levels[i]);
  return p;
}

Perturbation perturbation_factor(std::string_view factor, std::string_view level) {
  const std::size_t i = level_index(level);
  for (const auto& r : kTable)
    if (r.name == factor) {
      Perturbation p;
      set(p, factor, r.levels[i]);
      return p;
    }
  throw ConfigError("perturbation: factor \"" + std::string(factor) + "\" is not one of " + list(perturbation_factors()));
}

void validate(const Perturbation& p, const WorldConfig& world, const std::string& source) {
  auto require = [&](bool ok, const char* field, const std::string& rule, double got) {
    if (!ok || !std::isfinite(got)) {
      std::ostringstream text;
      text << source << ": field \"" << field << "\" must be " << rule << ", got " << got;
      throw ConfigError(text.str());
    }
  };
  const int room = std::min(kMaxActionDelay, world.episode.max_steps - 1);
  for (const auto& k : kKeys) {
    const double v = k.real ? p.*k.real : p.*k.whole;
    const double hi = k.whole ? room : k.hi;
    const std::string rule = k.whole ? "in [0, " + std::to_string(room) + "] (shorter than the episode's " +
                                           std::to_string(world.episode.max_steps) + " steps)"
                                     : range_text(k, hi);
    require(v >= 0 && (k.hi_open ? v < hi : v <= hi), k.name, rule, v);
  }
  if (p.delays_drawn && p.action_delay == 0 && p.observation_delay == 0)
    throw ConfigError(source + ": field \"" + kDelaysDrawn +
                      "\" draws each episode's delays from 0 to action_delay and observation_delay, and both are 0");
  // The widened starts must still fit inside the walls with the dice apart (the world's own
  // check); the physics factors stay in range by the bounds above.
  if (p.start_widening > 0) {
    WorldConfig wide = world;
    auto& r = wide.randomization;
    for (double* range : {&r.shift, &r.cup_lift, &r.cup_tilt}) *range *= 1.0 + p.start_widening;
    try {
      validate(wide);
    } catch (const ConfigError& e) {
      throw ConfigError(source + ": field \"start_widening\" " + std::to_string(p.start_widening) +
                        " makes starts that do not fit this world (" + e.what() + ")");
    }
  }
}

std::vector<PerturbationKey> perturbation_keys() {
  std::vector<PerturbationKey> out;
  for (const auto& k : kKeys) {
    const std::string range = range_text(k, k.hi);
    out.push_back({k.name, k.real ? "number" : "integer", k.whole ? range + ", and shorter than the episode" : range,
                   k.meaning});
  }
  out.push_back({kDelaysDrawn, "boolean", "version 2",
                 "each episode's delays drawn uniformly from 0 to action_delay and observation_delay"});
  return out;
}

std::string perturbation_to_json(const Perturbation& p) {
  json j = json::object();
  j["format"] = kPerturbationFormat;
  j["version"] = kPerturbationVersion;
  for (const auto& k : kKeys) j[k.name] = k.real ? json(p.*k.real) : json(p.*k.whole);
  j[kDelaysDrawn] = p.delays_drawn;
  return j.dump(2) + "\n";
}

std::string perturbation_summary(const Perturbation& p) {
  std::ostringstream out;
  for (const auto& k : kKeys) {
    const double v = k.real ? p.*k.real : p.*k.whole;
    if (v != 0.0) out << (out.tellp() > 0 ? ", " : "") << k.name << ' ' << v;
  }
  if (p.delays_drawn) out << ", delays drawn from 0";
  return out.tellp() > 0 ? out.str() : "none";
}

Perturbation perturbation_from_json(std::string_view text, const std::string& source, const WorldConfig& world) {
  json j;
  try {
    j = parse_json_limited<json>(text, source);
  } catch (const json::exception& e) {
    throw InputError(source + ": not JSON (" + e.what() + ")");
  }
  if (!j.is_object() || j.value("format", json()) != kPerturbationFormat)
    throw InputError(source + ": not a perturbation file (no \"format\": \"" + std::string(kPerturbationFormat) + "\")");
  const json& v = j.value("version", json());
  if (!v.is_number_integer() || v.get<long long>() < 1)
    throw InputError(source + ": field \"version\" must be a positive integer");
  if (v.get<long long>() > kPerturbationVersion)
    throw InputError(source + ": format version " + std::to_string(v.get<long long>()) +
                     " is newer than this dicestack reads (" + std::to_string(kPerturbationVersion) + "); upgrade dicestack");
  Perturbation p;
  for (const auto& [key, value] : j.items()) {
    if (key == "format" || key == "version") continue;
    if (key == kDelaysDrawn) {
      if (v.get<long long>() < 2)
        throw InputError(source + ": field \"" + key + "\" is format version 2; this file says version 1");
      if (!value.is_boolean()) throw InputError(source + ": field \"" + key + "\" must be true or false");
      p.delays_drawn = value.get<bool>();
      continue;
    }
    const Key* k = nullptr;
    for (const auto& candidate : kKeys)
      if (key == candidate.name) k = &candidate;
    if (!k) throw InputError(source + ": unknown field \"" + key + "\"");
    if (k->real) {
      if (!value.is_number()) throw InputError(source + ": field \"" + key + "\" must be a number");
      p.*k->real = value.get<double>();
    } else {
      if (!value.is_number_integer()) throw InputError(source + ": field \"" + key + "\" must be an integer");
      const long long n = value.get<long long>();
      if (n < 0 || n > 1'000'000) throw InputError(source + ": field \"" + key + "\" must be in [0, 1000000]");
      p.*k->whole = static_cast<int>(n);
    }
  }
  validate(p, world, source);
  return p;
}

Perturbation load_perturbation(const std::string& level_or_file, const WorldConfig& world) {
  for (const auto& level : perturbation_levels())
    if (level_or_file == level) return perturbation_level(level);
  const std::filesystem::path path(level_or_file);
  std::error_code ec;
  if (std::filesystem::status(path, ec).type() == std::filesystem::file_type::not_found)
    throw InputError(level_or_file + ": not a perturbation level (none, easy, medium, hard) nor a file");
  return perturbation_from_json(read_file(path, kMaxSettingsFileBytes), level_or_file, world);
}

const State& observation_spread() {
  // Standard deviations of each component over the built-in set's 15,190 frames (the mpc
  // expert's 80 episodes), rounded; angles as recorded (unwrapped).
  static const State spread{1.5,  0.05, 0.47,                // cup x, y, angle
                            1.6,  0.54, 3.1,  5.9, 0.95, 3.1,  // die 0 x, y, angle, vx, vy, w
                            1.6,  0.54, 3.1,  5.9, 0.95, 3.1,  // die 1
                            1.6,  0.54, 3.1,  5.9, 0.95, 3.1,  // die 2
                            5.7,  0.54, 1.9};                  // cup vx, vy, w
  return spread;
}

PerturbationDraw draw_perturbation(const Perturbation& p, const WorldConfig& world, std::uint64_t episode_seed) {
  PerturbationDraw d;
  d.world = world;
  if (p.nominal()) return d;
  // Every quantity is drawn, in one fixed order, whatever the magnitudes: a factor's draw does
  // not depend on which other factors are on.
  Rng rng(derive_seed(episode_seed, kPerturbStream));
  auto scale = [&](double a) { return 1.0 + a * rng.uniform(-1.0, 1.0); };
  d.world.dice.friction *= scale(p.friction);
  d.world.cup.friction *= scale(p.friction);
  d.world.walls.friction *= scale(p.friction);
  d.world.dice.mass *= scale(p.dice_mass);
  d.world.cup.segment_mass *= scale(p.cup_mass);
  d.world.physics.gravity.y += p.gravity * rng.normal();
  for (std::size_t k = 0; k < kActionDim; ++k) {
    d.action_bias[k] = p.action_bias * world.action.scale[k] * rng.normal();
    d.action_noise[k] = p.action_noise * world.action.scale[k];
  }
  d.noise_seed = rng.next();
  const auto torque = action_scale(world, ActionKind::joint_torque);
  for (std::size_t k = 0; k < kJointCount; ++k) {
    d.torque_bias[k] = p.action_bias * torque[k] * rng.normal();
    d.torque_noise[k] = p.action_noise * torque[k];
  }
  d.action_delay = p.action_delay;
  for (std::size_t k = 0; k < kStateDim; ++k) d.observation_noise[k] = p.observation_noise * observation_spread()[k];
  d.observation_delay = p.observation_delay;
  if (p.delays_drawn) {
    Rng delays(derive_seed(episode_seed, kDelayStream));
    d.action_delay = static_cast<int>(delays.below(static_cast<std::uint64_t>(p.action_delay) + 1));
    d.observation_delay = static_cast<int>(delays.below(static_cast<std::uint64_t>(p.observation_delay) + 1));
  }
  auto& r = d.world.randomization;
  for (double* range : {&r.shift, &r.cup_lift, &r.cup_tilt}) *range *= 1.0 + p.start_widening;
  d.physics = p.friction > 0 || p.dice_mass > 0 || p.cup_mass > 0 || p.gravity > 0 || p.start_widening > 0;
  d.acts = p.action_noise > 0 || p.action_bias > 0 || p.action_delay > 0 || p.observation_noise > 0 ||
           p.observation_delay > 0;
  return d;
}

std::string draw_to_json(const PerturbationDraw& d, ActionKind actions) {
  const WorldConfig& w = d.world;
  json j{{"dice_friction", w.dice.friction},
         {"cup_friction", w.cup.friction},
         {"walls_friction", w.walls.friction},
         {"dice_mass", w.dice.mass},
         {"cup_segment_mass", w.cup.segment_mass},
         {"gravity_y", w.physics.gravity.y},
         {"action_bias", d.action_bias},
         {"action_noise_std", d.action_noise},
         {"action_delay", d.action_delay},
         {"observation_noise_std", d.observation_noise},
         {"observation_delay", d.observation_delay},
         {"start_shift", w.randomization.shift},
         {"start_cup_lift", w.randomization.cup_lift},
         {"start_cup_tilt", w.randomization.cup_tilt},
         {"noise_seed", d.noise_seed}};
  // Only an episode in joint torques met them; any other's record stays as it was.
  if (actions == ActionKind::joint_torque) {
    j["joint_torque_bias"] = d.torque_bias;
    j["joint_torque_noise_std"] = d.torque_noise;
  }
  return j.dump();
}

PerturbationDraw channel_draw_from_json(std::string_view text, const std::string& source) {
  const json j = json::parse(text, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw InputError(source + ": its perturbation must be a JSON object");
  auto bad = [&](const char* key, const std::string& what) {
    return InputError(source + ": its perturbation's \"" + std::string(key) + "\" must be " + what);
  };
  // A field left out is nominal (a set written by hand may name only what it perturbed).
  auto reals = [&](const char* key, std::span<double> out, bool std_dev) {
    if (!j.contains(key)) return;
    const json& v = j[key];
    const std::string what = std::to_string(out.size()) + (std_dev ? " standard deviations >= 0" : " finite numbers");
    if (!v.is_array() || v.size() != out.size()) throw bad(key, what);
    for (std::size_t k = 0; k < out.size(); ++k) {
      if (!v[k].is_number() || !std::isfinite(v[k].get<double>()) || std::abs(v[k].get<double>()) > 1e6 ||
          (std_dev && v[k].get<double>() < 0))
        throw bad(key, what);
      out[k] = v[k].get<double>();
    }
  };
  auto steps = [&](const char* key) {
    if (!j.contains(key)) return 0;
    const json& v = j[key];
    if (!v.is_number_unsigned() || v.get<std::uint64_t>() > static_cast<std::uint64_t>(kMaxActionDelay))
      throw bad(key, "a whole number of steps in [0, " + std::to_string(kMaxActionDelay) + "]");
    return static_cast<int>(v.get<std::uint64_t>());
  };
  PerturbationDraw d;
  reals("action_bias", d.action_bias, false);
  reals("action_noise_std", d.action_noise, true);
  reals("observation_noise_std", d.observation_noise, true);
  reals("joint_torque_bias", d.torque_bias, false);
  reals("joint_torque_noise_std", d.torque_noise, true);
  d.action_delay = steps("action_delay");
  d.observation_delay = steps("observation_delay");
  // What the policy saw is replayed from the seed only under observation noise (the action
  // noise drawn from the same stream shows in no observation by itself).
  const bool seen_noise = std::any_of(d.observation_noise.begin(), d.observation_noise.end(), [](double v) { return v > 0; });
  if (j.contains("noise_seed")) {
    if (!j["noise_seed"].is_number_unsigned()) throw bad("noise_seed", "a whole number");
    d.noise_seed = j["noise_seed"].get<std::uint64_t>();
  } else if (seen_noise) {
    throw InputError(source + ": its perturbation has observation noise but no \"noise_seed\" to replay it from");
  }
  d.acts = true;
  return d;
}

PerturbedChannel::PerturbedChannel(const PerturbationDraw& draw, ActionKind actions)
    : draw_(draw),
      noise_(draw.noise_seed),
      chosen_(static_cast<std::size_t>(draw.action_delay), Action::zeros(actions)),
      actions_(actions) {}

State PerturbedChannel::observe(const State& state) {
  states_.push_back(state);
  if (states_.size() > static_cast<std::size_t>(draw_.observation_delay) + 1) states_.pop_front();
  State seen = states_.front();
  for (std::size_t k = 0; k < kStateDim; ++k)
    if (draw_.observation_noise[k] > 0.0) seen[k] += draw_.observation_noise[k] * noise_.normal();
  return seen;
}

Action PerturbedChannel::execute(const Action& chosen) {
  if (chosen.kind() != actions_)
    throw InputError("a choice for the " + std::string(action_kind_name(chosen.kind())) + " controller, where the policy answers " +
                     std::string(action_kind_name(actions_)) + " actions");
  chosen_.push_back(chosen);  // holds action_delay zeros from the start: nothing runs before then
  Action a = chosen_.front();
  chosen_.pop_front();
  ran_.push_back(a);
  if (ran_.size() > static_cast<std::size_t>(draw_.observation_delay)) ran_.pop_front();
  const bool cup = a.kind() == ActionKind::cup;
  const Action& bias = cup ? draw_.action_bias : draw_.torque_bias;
  const Action& noise = cup ? draw_.action_noise : draw_.torque_noise;
  for (std::size_t k = 0; k < a.size(); ++k) {
    a[k] += bias[k];
    if (noise[k] > 0.0) a[k] += noise[k] * noise_.normal();
  }
  return a;
}

}  // namespace dicestack
