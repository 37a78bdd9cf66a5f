// The tracker's named presets and its settings by name (tracker.hpp): one vocabulary, the
// config's field names, for record, robustness, Python, the bench and the learners.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string>

#include <dicestack/core/error.hpp>
#include <dicestack/core/tracker.hpp>

namespace dicestack {
namespace {

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

[[noreturn]] void bad_setting(std::string_view name, std::string_view value, const std::string& takes) {
  throw ConfigError("tracker setting " + std::string(name) + ": " + takes + ", got \"" + std::string(value) + "\"");
}

int whole_number(std::string_view name, std::string_view value) {
  int out = 0;
  const auto r = std::from_chars(value.data(), value.data() + value.size(), out);
  if (r.ec != std::errc() || r.ptr != value.data() + value.size()) bad_setting(name, value, "takes a whole number");
  return out;
}

double real_number(std::string_view name, std::string_view value) {
  double out = 0.0;
  const auto r = std::from_chars(value.data(), value.data() + value.size(), out);
  if (r.ec != std::errc() || r.ptr != value.data() + value.size() || !std::isfinite(out))
    bad_setting(name, value, "takes a number");
  return out;
}

bool yes_or_no(std::string_view name, std::string_view value) {
  if (value == "true") return true;
  if (value == "false") return false;
  bad_setting(name, value, "takes true or false");
}

}  // namespace

TrackerConfig tracker_preset(std::string_view name) {
  TrackerConfig c;
  if (name == "plain") return c;
  if (name == "distill") {
    c.paths = 3;
    c.smooth = 4.0;
    c.robust = 5;
    c.robust_warp = 0.02;
    c.shrink = 5;
    c.variants.assign(kTrackerVariantWidths.begin(), kTrackerVariantWidths.end());
    c.refine = 60;
    c.refine_restarts = 4;
    return c;
  }
  throw ConfigError("tracker preset \"" + std::string(name) + "\": unknown; presets: " + joined(tracker_preset_names()));
}

std::vector<std::string> tracker_preset_names() { return {"plain", "distill"}; }

std::vector<std::string> tracker_setting_names() {
  return {"probes", "optimise", "paths", "smooth", "rescue", "robust", "robust_noise", "robust_warp", "keep_extremes",
          "shrink", "variants", "refine", "refine_probes", "refine_restarts", "refine_timing"};
}

void settle_for_joint_torques(TrackerConfig& c, const std::function<bool(std::string_view)>& given) {
  constexpr int kProbes = 32;
  c.controller = ActionKind::joint_torque;
  if (!given("refine")) c.refine = 0;
  if (!given("probes")) set_tracker_setting(c, "probes", std::to_string(std::max(c.probes, kProbes)));
}

void set_tracker_setting(TrackerConfig& c, std::string_view name, std::string_view value) {
  if (name == "probes") {
    c.probes = whole_number(name, value);
    c.finalist_probes = 4 * c.probes;
  } else if (name == "optimise") {
    c.optimise = yes_or_no(name, value);
  } else if (name == "paths") {
    c.paths = whole_number(name, value);
  } else if (name == "smooth") {
    c.smooth = real_number(name, value);
  } else if (name == "rescue") {
    c.rescue = whole_number(name, value);
  } else if (name == "robust") {
    c.robust = whole_number(name, value);
  } else if (name == "robust_noise") {
    c.robust_noise = real_number(name, value);
  } else if (name == "robust_warp") {
    c.robust_warp = real_number(name, value);
  } else if (name == "keep_extremes") {
    c.keep_extremes = yes_or_no(name, value);
  } else if (name == "shrink") {
    c.shrink = whole_number(name, value);
  } else if (name == "refine") {
    c.refine = whole_number(name, value);
  } else if (name == "refine_probes") {
    c.refine_probes = whole_number(name, value);
  } else if (name == "refine_restarts") {
    c.refine_restarts = whole_number(name, value);
  } else if (name == "refine_timing") {
    c.refine_range[3] = real_number(name, value);
  } else if (name == "variants") {
    c.variants.clear();
    if (yes_or_no(name, value)) c.variants.assign(kTrackerVariantWidths.begin(), kTrackerVariantWidths.end());
  } else {
    throw ConfigError("tracker setting \"" + std::string(name) + "\": unknown; settings: " + joined(tracker_setting_names()));
  }
}

std::string tracker_setting_text(const TrackerConfig& c, std::string_view name) {
  const auto number = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.17g", v);
    return std::string(text);
  };
  const auto flag = [](bool v) { return std::string(v ? "true" : "false"); };
  if (name == "probes") return std::to_string(c.probes);
  if (name == "optimise") return flag(c.optimise);
  if (name == "paths") return std::to_string(c.paths);
  if (name == "smooth") return number(c.smooth);
  if (name == "rescue") return std::to_string(c.rescue);
  if (name == "robust") return std::to_string(c.robust);
  if (name == "robust_noise") return number(c.robust_noise);
  if (name == "robust_warp") return number(c.robust_warp);
  if (name == "keep_extremes") return flag(c.keep_extremes);
  if (name == "shrink") return std::to_string(c.shrink);
  if (name == "variants") return flag(!c.variants.empty());
  if (name == "refine") return std::to_string(c.refine);
  if (name == "refine_probes") return std::to_string(c.refine_probes);
  if (name == "refine_restarts") return std::to_string(c.refine_restarts);
  if (name == "refine_timing") return number(c.refine_range[3]);
  throw ConfigError("tracker setting \"" + std::string(name) + "\": unknown; settings: " + joined(tracker_setting_names()));
}

std::string tracker_summary(const TrackerConfig& c) {
  std::string out;
  for (const auto& name : tracker_setting_names()) out += (out.empty() ? "" : ", ") + name + "=" + tracker_setting_text(c, name);
  return out;
}

TrackerConfig tracker_config(std::string_view preset, const std::vector<std::string>& settings) {
  TrackerConfig c = tracker_preset(preset);
  for (const auto& s : settings) {
    const std::size_t eq = s.find('=');
    if (eq == std::string::npos || eq == 0)
      throw ConfigError("tracker setting \"" + s + "\": give NAME=VALUE; settings: " + joined(tracker_setting_names()));
    set_tracker_setting(c, std::string_view(s).substr(0, eq), std::string_view(s).substr(eq + 1));
  }
  validate(c);
  return c;
}

}  // namespace dicestack
