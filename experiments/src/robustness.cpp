#include <dicestack/experiments/robustness.hpp>

#include <algorithm>

#include <cstdio>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/experiments/results_page.hpp>
#include <dicestack/version.hpp>

#include <dicestack/pages/page.hpp>
#include <dicestack/pages/resources.hpp>

namespace dicestack {
namespace {

constexpr const char* kMarker = "<!-- dicestack robustness -->";
constexpr const char* kCsvHeader =
    "factor,level,realistic_success,realistic_success_low,realistic_success_high,wall_contact,dice_in_cup_mean,episodes";
constexpr const char* kJsonFormat = "dicestack-robustness";

bool sensing(const std::string& factor) { return factor == "observation_noise" || factor == "observation_delay"; }

std::string percent(const Rate& r, int n) {
  char s[64];
  std::snprintf(s, sizeof s, "%.0f%% [%.0f-%.0f] (%d)", 100 * r.value, 100 * r.low, 100 * r.high,
                static_cast<int>(r.value * n + 0.5));
  return s;
}

}  // namespace

void check_robustness_factors(const std::vector<std::string>& factors) {
  const auto& known = perturbation_factors();
  for (const auto& f : factors)
    if (f != "none" && f != "all" && std::find(known.begin(), known.end(), f) == known.end()) {
      std::string names = "none, all";
      for (const auto& k : known) names += ", " + k;
      throw ConfigError("robustness: unknown factor \"" + f + "\"; known: " + names);
    }
}

std::vector<RobustnessRow> robustness(const PolicyFactory& make_policy, const WorldConfig& world,
                                      const RobustnessRequest& request, Cluster& cluster) {
  check_robustness_factors(request.factors);
  const auto& known = perturbation_factors();
  auto wanted = [&](const std::string& f) {
    return request.factors.empty() || std::find(request.factors.begin(), request.factors.end(), f) != request.factors.end();
  };
  std::vector<std::pair<std::string, std::string>> plan;
  if (wanted("none")) plan.emplace_back("none", "none");
  for (const auto& f : known) {
    if ((request.reads_world && sensing(f)) || !wanted(f)) continue;
    for (const char* level : {"easy", "medium", "hard"}) plan.emplace_back(f, level);
  }
  if (wanted("all"))
    for (const char* level : {"easy", "medium", "hard"}) plan.emplace_back("all", level);
  if (plan.empty())
    throw ConfigError("robustness: no row to measure: an expert reads the world itself, so its table leaves out the "
                      "sensing factors (observation_noise, observation_delay)");
  // Every perturbation is checked against the world before any row runs.
  auto perturbation = [&](const std::string& f, const std::string& level) {
    Perturbation p = f == "none" ? Perturbation{} : f == "all" ? perturbation_level(level) : perturbation_factor(f, level);
    if (request.reads_world) p.observation_noise = 0.0, p.observation_delay = 0;
    return p;
  };
  for (const auto& [f, level] : plan) {
    EvalRequest row;
    row.episodes = request.episodes;
    row.threads = request.threads;
    row.perturbation = perturbation(f, level);
    row.actions = request.actions;
    row.estimator = request.estimator;
    check_evaluation(world, row);
  }
  std::vector<RobustnessRow> rows;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const auto& [f, level] = plan[i];
    if (request.progress) request.progress(static_cast<int>(i), static_cast<int>(plan.size()), f, level);
    EvalRequest r;
    r.episodes = request.episodes;
    r.seed = request.seed;
    r.threads = request.threads;
    r.perturbation = perturbation(f, level);
    r.estimator = request.estimator;
    r.actions = request.actions;
    rows.push_back({f, level, evaluate(make_policy, world, r, cluster)});
  }
  return rows;
}

RobustnessTable robustness_table(std::vector<RobustnessRow> rows, const RobustnessRun& run) {
  RobustnessTable t;
  t.rows = std::move(rows);
  t.header = "dicestack robustness: " + run.policy + "; " + std::to_string(run.episodes) +
             " rollouts per row from evaluation starts (seed " + std::to_string(run.seed) +
             "); rates with 95% Wilson intervals (successes)" +
             (run.reads_world ? "; sensing factors left out (an expert reads the world itself)" : "") +
             (run.estimator.empty() || run.estimator == "none" ? "" : "; under the sensing factors the policy sees the " +
                                                                         run.estimator + " estimator's estimate");
  nlohmann::json meta{{"policy", run.policy},
                      {"world", run.world},
                      {"rollouts_per_row", run.episodes},
                      {"seed", run.seed},
                      {"dicestack_version", DICESTACK_VERSION}};
  if (run.reads_world) meta["sensing_factors"] = "left out (an expert reads the world itself)";
  if (!run.estimator.empty() && run.estimator != "none") meta["estimator"] = run.estimator;
  if (!run.record.empty()) meta["model_record"] = run.record;
  t.meta_json = meta.dump();
  return t;
}

namespace {

nlohmann::json rate_triple(const Rate& r) { return {r.value, r.low, r.high}; }

nlohmann::json robustness_row_json(const RobustnessRow& r) {
  return {{"factor", r.factor},
          {"level", r.level},
          {"episodes", r.stats.episodes},
          {"realistic_success_rate", r.stats.realistic_success.value},
          {"realistic_success_rate_ci95", rate_triple(r.stats.realistic_success)},
          {"wall_contact_rate", r.stats.wall_contact.value},
          {"wall_contact_rate_ci95", rate_triple(r.stats.wall_contact)},
          {"dice_in_cup_mean", r.stats.dice_in_cup_mean}};
}

std::string robustness_md(const RobustnessTable& t) {
  std::ostringstream out;
  out << kMarker << '\n' << t.header << "\n\n| factor | level | realistic success | wall contact | dice in cup | episodes |\n"
      << "|---|---|---:|---:|---:|---:|\n";
  for (const auto& r : t.rows) {
    char cup[32];
    std::snprintf(cup, sizeof cup, "%.2f", r.stats.dice_in_cup_mean);
    out << "| " << r.factor << " | " << r.level << " | " << percent(r.stats.realistic_success, r.stats.episodes) << " | "
        << percent(r.stats.wall_contact, r.stats.episodes) << " | " << cup << " | " << r.stats.episodes << " |\n";
  }
  return out.str();
}

std::string robustness_csv(const RobustnessTable& t) {
  std::ostringstream out;
  out << kCsvHeader << '\n';
  for (const auto& r : t.rows) {
    const Rate& s = r.stats.realistic_success;
    out << r.factor << ',' << r.level << ',' << s.value << ',' << s.low << ',' << s.high << ','
        << r.stats.wall_contact.value << ',' << r.stats.dice_in_cup_mean << ',' << r.stats.episodes << '\n';
  }
  return out.str();
}

std::string robustness_json(const RobustnessTable& t) {
  nlohmann::json j = t.meta_json.empty() ? nlohmann::json::object() : nlohmann::json::parse(t.meta_json);
  j["format"] = kJsonFormat;
  j["version"] = 1;
  j["header"] = t.header;
  j["rows"] = nlohmann::json::array();
  for (const auto& r : t.rows) j["rows"].push_back(robustness_row_json(r));
  return j.dump(2) + '\n';
}

// The page's data: the json format's settings as facts, and its rows with what the shared
// table reads (rank, and each rate's interval as [low, high] under KEY_ci95).
std::string robustness_html(const RobustnessTable& t) {
  const nlohmann::json meta = t.meta_json.empty() ? nlohmann::json::object() : nlohmann::json::parse(t.meta_json);
  nlohmann::json facts = nlohmann::json::array();
  for (auto it = meta.begin(); it != meta.end(); ++it) facts.push_back({it.key(), it.value()});
  nlohmann::json rows = nlohmann::json::array();
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const RobustnessRow& r = t.rows[i];
    nlohmann::json row = robustness_row_json(r);
    row["rank"] = i + 1;
    row["successes"] = static_cast<int>(r.stats.realistic_success.value * r.stats.episodes + 0.5);
    row["realistic_success_ci95"] = {r.stats.realistic_success.low, r.stats.realistic_success.high};
    row["wall_contact_ci95"] = {r.stats.wall_contact.low, r.stats.wall_contact.high};
    rows.push_back(std::move(row));
  }
  std::string title = "dicestack robustness";
  if (meta.contains("policy")) title += ": " + meta.at("policy").get<std::string>();
  const nlohmann::json data{{"title", title}, {"header", t.header}, {"facts", facts}, {"rows", rows}};
  return std::string(kResultsPageMarker) + '\n' + page::table_page_html(data.dump(), page::resource::robustness_js);
}

}  // namespace

const std::vector<RobustnessFormat>& robustness_formats() {
  static const std::vector<RobustnessFormat> formats{
      {"md", ".md", "the header line, then a Markdown table", robustness_md,
       [] { return Ownership::first_line("dicestack robustness table (md)", {kMarker}); }},
      {"csv", ".csv", "a row per line, realistic success with its interval", robustness_csv,
       [] { return Ownership::first_line("dicestack robustness table (csv)", {kCsvHeader}); }},
      {"json", ".json", "the settings, the header line and a \"rows\" array", robustness_json,
       [] { return Ownership::json_object("dicestack robustness table (json)", kJsonFormat); }},
      {"html", ".html", "a page for a browser: the table sortable by any column, the settings (docs/results-pages.md)",
       robustness_html, [] { return results_page_ownership(); }, "md"},
  };
  return formats;
}

const RobustnessFormat& robustness_format(const std::string& name) {
  std::string names;
  for (const RobustnessFormat& f : robustness_formats()) {
    if (f.name == name) return f;
    names += (names.empty() ? "" : ", ") + f.name;
  }
  throw ConfigError("robustness: format \"" + name + "\" is not one of " + names);
}

std::string render_robustness(const RobustnessTable& table, const std::string& format) {
  return robustness_format(format).render(table);
}

void check_robustness_out(const std::filesystem::path& out, const std::string& format) {
  check_replaceable(out, robustness_format(format).ownership());  // an unknown format fails first
}

void write_robustness(const RobustnessTable& table, const std::string& format, const std::filesystem::path& out) {
  const RobustnessFormat& f = robustness_format(format);
  const std::string text = f.render(table);
  AtomicFile file(out, f.ownership());
  file.stream() << text;
  file.commit();
}

}  // namespace dicestack
