#include "options.hpp"

#include <dicestack/core/estimator.hpp>

#include <algorithm>
#include <cstdio>
#include <iostream>

#include <unistd.h>

#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/experiments/train.hpp>
#include <dicestack/learners/learner.hpp>

namespace dicestack::cli {

void WorldOption::add_to(CLI::App& app, bool starts) {
  app.add_option("--world", path, "World config JSON (defaults: the paper's world; see `dicestack config`)")
      ->check(CLI::ExistingFile);
  app.add_option("--embodiment", embodiment,
                 "What moves the cup: cup (the paper's floating cup) or arm (a planar arm holds it; docs/arm.md). "
                 "Default: the world config's")
      ->check(CLI::IsMember({"cup", "arm"}));
  if (starts)
    app.add_option("--start", start,
                   "Where episodes start: random (the world's randomization) or paper (the paper's start at rest, the "
                   "whole scene shifted in x by U(-2 cm, 2 cm) per episode)")
        ->check(CLI::IsMember(start_names()))
        ->capture_default_str();
}

WorldConfig WorldOption::load() const {
  WorldConfig config = with_starts(path.empty() ? WorldConfig{} : load_world_config(path), start);
  if (embodiment.empty()) return config;
  config.embodiment = embodiment == "arm" ? Embodiment::arm : Embodiment::cup;
  try {
    validate(config);
  } catch (const ConfigError& e) {
    throw ConfigError(std::string("--embodiment ") + embodiment + ": " + e.what());
  }
  return config;
}

void TrackerOption::add_to(CLI::App& app) {
  const auto listed = [](const std::vector<std::string>& names) {
    std::string out;
    for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
    return out;
  };
  const std::string presets = listed(tracker_preset_names()), names = listed(tracker_setting_names());
  app.add_option("--tracker-preset", preset,
                 "tracker: its named settings (" + presets + "; distill is the learners' default, docs/expert.md)")
      ->check(CLI::IsMember(tracker_preset_names()))
      ->capture_default_str();
  app.add_option("--tracker", settings, "tracker: a setting on top of the preset, NAME=VALUE, repeatable (" + names + ")");
}

TrackerConfig TrackerOption::config_for(ActionKind controller) const {
  TrackerConfig tracker = config();
  tracker.controller = controller;
  if (controller == ActionKind::joint_torque)
    settle_for_joint_torques(tracker, [&](std::string_view name) {
      return std::any_of(settings.begin(), settings.end(), [&](const std::string& s) { return s.rfind(std::string(name) + "=", 0) == 0; });
    });
  return tracker;
}

std::string TrackerOption::as_arguments() const {
  std::string out = preset == "plain" ? "" : " --tracker-preset " + preset;
  for (const auto& s : settings) out += " --tracker " + s;
  return out;
}

void print_line(const std::string& text) { std::cout << text << '\n' << std::flush; }

void print_progress(const std::string& text) {
  static const bool tty = isatty(fileno(stderr));
  if (tty) std::cerr << "\r\033[K" << text << std::flush;
  else std::cerr << text << '\n';
}

namespace {

std::string clock_text(double seconds) {
  const auto s = static_cast<long>(seconds + 0.5);
  char out[32];
  if (s >= 3600) std::snprintf(out, sizeof out, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  else std::snprintf(out, sizeof out, "%ld:%02ld", s / 60, s % 60);
  return out;
}

}  // namespace

ProgressBar::ProgressBar(double quiet_seconds)
    : start_(std::chrono::steady_clock::now()), last_print_(start_), quiet_(quiet_seconds) {}

void ProgressBar::update(double fraction, const std::string& text) {
  static const bool tty = isatty(fileno(stderr));
  const auto now = std::chrono::steady_clock::now();
  if (counted_fraction_ < 0.0 && fraction > 0.0) {
    counted_from_ = now;
    counted_fraction_ = std::min(fraction, 1.0);
  }
  if (!tty && printed_ && std::chrono::duration<double>(now - last_print_).count() < quiet_) return;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  constexpr int width = 20;
  const int filled = static_cast<int>(fraction * width);
  std::string line = "[" + std::string(static_cast<std::size_t>(filled), '#') + std::string(static_cast<std::size_t>(width - filled), '-') + "] ";
  char pct[16];
  std::snprintf(pct, sizeof pct, "%3.0f%% ", 100.0 * fraction);
  line += pct + text + "  elapsed " + clock_text(elapsed);
  const double left =
      counted_fraction_ < 0.0 ? -1.0 : time_left(std::chrono::duration<double>(now - counted_from_).count(), fraction, counted_fraction_);
  if (left >= 0.0) line += ", left ~" + clock_text(left);
  print_progress(line);
  last_print_ = now;
  printed_ = true;
}

void ProgressBar::finish() {
  static const bool tty = isatty(fileno(stderr));
  if (tty && printed_) std::cerr << '\n';
}

void DemosOption::add_to(CLI::App& app) {
  app.add_option("--demos", path,
                 "Demonstration folder, or `builtin` (default: 80 expert successes) or `human` (the paper's 68 "
                 "recordings, converted)");
}

std::filesystem::path DemosOption::resolve(const WorldConfig& world) const { return resolve_demo_set(path, world); }

std::filesystem::path DemosOption::resolve(const WorldConfig& world, Cluster& cluster) const {
  return on_root(cluster, [&] { return resolve(world).string(); });
}

CLI::Validator threads_check() {
  return CLI::Validator(
      [](const std::string& text) -> std::string {
        try {
          std::size_t used = 0;
          const long long n = std::stoll(text, &used);
          if (used == text.size() && n >= 0 && n <= kMaxThreads) return "";
        } catch (const std::exception&) {
        }
        return "threads is a whole number in [0, " + std::to_string(kMaxThreads) +
               "] (0: all cores; results do not depend on it), got \"" + text.substr(0, 40) + "\"";
      },
      "THREADS");
}

CLI::Option* add_controller_option(CLI::App& cmd, std::string& name, const std::string& help) {
  return cmd.add_option("--controller", name, help)->check(CLI::IsMember({"cup", "joint_torque"}))->capture_default_str();
}

ActionKind controller_kind(const std::string& name) {
  return name == "joint_torque" ? ActionKind::joint_torque : ActionKind::cup;
}

CLI::Option* add_expert_controller_option(CLI::App& cmd, std::string& name) {
  return add_controller_option(cmd, name,
                               "What the expert answers on the arm: cup (the cup's velocity change) or joint_torque (its cup "
                               "actions told in the joint torques the cup controller held)");
}

CLI::Option* add_estimator_option(CLI::App& cmd, std::string& name) {
  return cmd
      .add_option("--estimator", name,
                  "What the policy is shown under sensing factors and delays: none (the observations), kalman (a "
                  "Kalman filter whose motion model is the simulator) or particle (a particle filter of simulated "
                  "worlds, 64; particle:N for N; docs/robustness.md). Default: the model's own (a policy trained "
                  "with perturb= runs behind the estimator it names), none otherwise")
      ->check(CLI::Validator(
          [](std::string& value) {
            try {
              estimator_config(value);
              return std::string();
            } catch (const ConfigError& e) {
              return std::string(e.what());
            }
          },
          "none|kalman|particle[:N]"));
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

CLI::Validator seed_check() {
  return CLI::Validator(
      [](const std::string& text) -> std::string {
        const std::string max = "18446744073709551615";
        // Digits only, and no leading zero: CLI11 2.1 would read "010" as octal 8.
        const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos &&
                            (text.size() == 1 || text[0] != '0');
        if (!digits || text.size() > max.size() || (text.size() == max.size() && text > max))
          return "a seed is a whole number in [0, " + max + "] without leading zeros, got \"" + text.substr(0, 40) + "\"";
        return {};
      },
      "SEED");
}

}  // namespace dicestack::cli
