#include <dicestack/learners/robustness.hpp>

#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

constexpr const char* kMarker = "<!-- dicestack robustness -->";
constexpr const char* kCsvHeader =
    "factor,level,realistic_success,realistic_success_low,realistic_success_high,wall_contact,dice_in_cup_mean,episodes";
constexpr const char* kJsonFormat = "dicestack-robustness";

Ownership robustness_ownership(const std::string& format) {
  if (format == "json") return Ownership::json_object("dicestack robustness table (json)", kJsonFormat);
  if (format == "csv") return Ownership::first_line("dicestack robustness table (csv)", {kCsvHeader});
  return Ownership::first_line("dicestack robustness table (md)", {kMarker});
}

bool sensing(const std::string& factor) { return factor == "observation_noise" || factor == "observation_delay"; }

std::string percent(const Rate& r, int n) {
  char s[64];
  std::snprintf(s, sizeof s, "%.0f%% [%.0f-%.0f] (%d)", 100 * r.value, 100 * r.low, 100 * r.high,
                static_cast<int>(r.value * n + 0.5));
  return s;
}

}  // namespace

std::vector<RobustnessRow> robustness(const PolicyFactory& make_policy, const WorldConfig& world,
                                      const RobustnessRequest& request, Cluster& cluster) {
  std::vector<std::pair<std::string, std::string>> plan{{"none", "none"}};
  for (const auto& f : perturbation_factors()) {
    if (request.reads_world && sensing(f)) continue;
    for (const char* level : {"easy", "medium", "hard"}) plan.emplace_back(f, level);
  }
  for (const char* level : {"easy", "medium", "hard"}) plan.emplace_back("all", level);
  // Every perturbation is checked against the world before any row runs.
  auto perturbation = [&](const std::string& f, const std::string& level) {
    Perturbation p = f == "none" ? Perturbation{} : f == "all" ? perturbation_level(level) : perturbation_factor(f, level);
    if (request.reads_world) p.observation_noise = 0.0, p.observation_delay = 0;
    return p;
  };
  for (const auto& [f, level] : plan) validate(perturbation(f, level), world);
  std::vector<RobustnessRow> rows;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const auto& [f, level] = plan[i];
    if (request.progress) request.progress(static_cast<int>(i), static_cast<int>(plan.size()), f, level);
    EvalRequest r;
    r.episodes = request.episodes;
    r.seed = request.seed;
    r.threads = request.threads;
    r.perturbation = perturbation(f, level);
    rows.push_back({f, level, evaluate(make_policy, world, r, cluster)});
  }
  return rows;
}

std::string render_robustness(const std::vector<RobustnessRow>& rows, const std::string& format, const std::string& header) {
  std::ostringstream out;
  if (format == "md") {
    out << kMarker << '\n' << header << "\n\n| factor | level | realistic success | wall contact | dice in cup | episodes |\n"
        << "|---|---|---:|---:|---:|---:|\n";
    for (const auto& r : rows) {
      char cup[32];
      std::snprintf(cup, sizeof cup, "%.2f", r.stats.dice_in_cup_mean);
      out << "| " << r.factor << " | " << r.level << " | " << percent(r.stats.realistic_success, r.stats.episodes)
          << " | " << percent(r.stats.wall_contact, r.stats.episodes) << " | " << cup << " | " << r.stats.episodes
          << " |\n";
    }
  } else if (format == "csv") {
    out << kCsvHeader << '\n';
    for (const auto& r : rows) {
      const Rate& s = r.stats.realistic_success;
      out << r.factor << ',' << r.level << ',' << s.value << ',' << s.low << ',' << s.high << ','
          << r.stats.wall_contact.value << ',' << r.stats.dice_in_cup_mean << ',' << r.stats.episodes << '\n';
    }
  } else if (format == "json") {
    nlohmann::json j{{"format", kJsonFormat}, {"version", 1}, {"header", header}, {"rows", nlohmann::json::array()}};
    for (const auto& r : rows) {
      const Rate& s = r.stats.realistic_success;
      j["rows"].push_back({{"factor", r.factor},
                           {"level", r.level},
                           {"episodes", r.stats.episodes},
                           {"realistic_success_rate", s.value},
                           {"realistic_success_rate_ci95", {s.value, s.low, s.high}},
                           {"wall_contact_rate", r.stats.wall_contact.value},
                           {"dice_in_cup_mean", r.stats.dice_in_cup_mean}});
    }
    out << j.dump(2) << '\n';
  } else {
    throw ConfigError("robustness: format \"" + format + "\" is not one of md, csv, json");
  }
  return out.str();
}

void check_robustness_out(const std::filesystem::path& out, const std::string& format) {
  render_robustness({}, format, "");  // an unknown format fails here, before any work
  check_replaceable(out, robustness_ownership(format));
}

void write_robustness(const std::vector<RobustnessRow>& rows, const std::string& format, const std::string& header,
                      const std::filesystem::path& out) {
  const std::string table = render_robustness(rows, format, header);
  AtomicFile f(out, robustness_ownership(format));
  f.stream() << table;
  f.commit();
}

}  // namespace dicestack
