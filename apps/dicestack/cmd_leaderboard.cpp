// `dicestack leaderboard`: the paper's Table I regenerated: every regressor under every
// learner, with train and test error (eq. 9), rollout outcomes with 95% intervals, fit time and
// time per step. Interrupted runs resume from <out>.partial.json.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/metrics.hpp>
#include <dicestack/core/open_loop.hpp>
#include <dicestack/core/reinforce.hpp>
#include <dicestack/core/rrt.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/version.hpp>

#include "cli.hpp"
#include "options.hpp"

namespace dicestack::cli {
namespace {

using nlohmann::json;

struct LeaderboardOptions {
  WorldOption world;
  DemosOption demos;
  std::vector<std::string> regressors, learners, options, baselines, features;
  std::string profile = "quick", format = "md", split = "episodes";
  int episodes = 0, seeds = 1, threads = 0;
  std::uint64_t seed = 0;
  std::filesystem::path out;
};

struct Row {
  std::string regressor, learner, features = "-";
  double train_error = 0, test_error = 0, fit_s = 0, us_per_step = 0, dice_in_cup = 0;
  int episodes = 0, stacked = 0, walls = 0, success = 0;
};

json row_json(const Row& r) {
  const Rate st = wilson(r.stacked, r.episodes), wc = wilson(r.walls, r.episodes), rs = wilson(r.success, r.episodes);
  return {{"regressor", r.regressor},     {"learner", r.learner},          {"features", r.features},
          {"train_error", r.train_error},
          {"test_error", r.test_error},   {"dice_in_cup_mean", r.dice_in_cup}, {"episodes", r.episodes},
          {"stacked", r.stacked},         {"wall_contact", r.walls},       {"realistic_success", r.success},
          {"stacked_rate", st.value},     {"stacked_ci95", {st.low, st.high}},
          {"wall_contact_rate", wc.value}, {"wall_contact_ci95", {wc.low, wc.high}},
          {"realistic_success_rate", rs.value}, {"realistic_success_ci95", {rs.low, rs.high}},
          {"fit_s", r.fit_s},             {"us_per_step", r.us_per_step}};
}

void add_outcomes(Row& row, const EvalStats& st, int seeds) {
  row.episodes += st.episodes;
  row.stacked += static_cast<int>(std::lround(st.stacked.value * st.episodes));
  row.walls += static_cast<int>(std::lround(st.wall_contact.value * st.episodes));
  row.success += static_cast<int>(std::lround(st.realistic_success.value * st.episodes));
  row.dice_in_cup += st.dice_in_cup_mean / seeds;
  row.us_per_step += st.policy_us_per_step / seeds;
}

// The network REINFORCE learned, acting on states.
class NetworkPolicy final : public Policy {
 public:
  NetworkPolicy(std::shared_ptr<const PolicyNetwork> net, const WorldConfig& world) : net_(std::move(net)), world_(world) {}
  Action act(const History& h) override { return net_->act(h.current(), world_); }
  std::string name() const override { return "reinforce"; }

 private:
  std::shared_ptr<const PolicyNetwork> net_;
  WorldConfig world_;
};

// Runs a baseline with the profile's budget: an open-loop sequence (optimisers, RRT) played
// from every start, or REINFORCE's network acting on the states.
PolicyFactory baseline_policy(const std::string& name, const WorldConfig& world, bool paper, std::uint64_t seed, int threads) {
  std::vector<Action> actions;
  if (name == "reinforce") {
    ReinforceOptions o;
    o.iterations = paper ? 1000 : 100;
    o.seed = seed;
    o.threads = threads;
    auto net = std::make_shared<const PolicyNetwork>(reinforce(world, o).policy);
    return [net, world] { return std::make_unique<NetworkPolicy>(net, world); };
  }
  if (name == "rrt") {
    RrtOptions o;
    o.nodes = paper ? 1000 : 100;
    o.seed = seed;
    o.threads = threads;
    actions = rrt(world, o).actions;
  } else {
    OptimiseOptions o;
    o.method = name;
    o.evaluations = name == "bayes" ? (paper ? 500 : 200) : (paper ? 5000 : 1000);
    o.seed = seed;
    OpenLoopProblem problem(world, {}, threads);
    actions = problem.actions(optimise(problem, o).best.data());
  }
  Episode sequence;
  sequence.actions = actions;
  return [sequence] { return std::make_unique<PlaybackPolicy>(sequence); };
}

Row row_from(const json& j) {
  Row r;
  r.regressor = j.at("regressor");
  r.learner = j.at("learner");
  r.features = j.value("features", "-");
  r.train_error = j.at("train_error");
  r.test_error = j.at("test_error");
  r.dice_in_cup = j.at("dice_in_cup_mean");
  r.episodes = j.at("episodes");
  r.stacked = j.at("stacked");
  r.walls = j.at("wall_contact");
  r.success = j.at("realistic_success");
  r.fit_s = j.at("fit_s");
  r.us_per_step = j.at("us_per_step");
  return r;
}

std::string pct(int k, int n) {
  const Rate r = wilson(k, n);
  char s[64];
  std::snprintf(s, sizeof s, "%.0f%% [%.0f-%.0f]", 100 * r.value, 100 * r.low, 100 * r.high);
  return s;
}

std::string fixed(double v, int digits) {
  if (v < 0) return "-";
  char s[32];
  std::snprintf(s, sizeof s, "%.*f", digits, v);
  return s;
}

constexpr const char* kLeaderboardFormat = "dicestack-leaderboard";
constexpr const char* kPartialFormat = "dicestack-leaderboard-partial";
constexpr const char* kCsvHeader =
    "regressor,learner,features,train_error,test_error,dice_in_cup_mean,stacked_rate,stacked_low,stacked_high,"
    "wall_contact_rate,realistic_success_rate,realistic_success_low,realistic_success_high,episodes,fit_s,us_per_step";
// The header before feature maps had a column (still ours to replace).
constexpr const char* kCsvHeaderV1 =
    "regressor,learner,train_error,test_error,dice_in_cup_mean,stacked_rate,stacked_low,stacked_high,"
    "wall_contact_rate,realistic_success_rate,realistic_success_low,realistic_success_high,episodes,fit_s,us_per_step";

// The first line a written table starts with (md and latex get a marker comment), and which
// existing files --out may replace: tables of the same format that dicestack wrote.
std::string file_marker(const std::string& format) {
  if (format == "md") return "<!-- dicestack leaderboard -->\n";
  if (format == "latex") return "% dicestack leaderboard\n";
  return "";
}

Ownership table_ownership(const std::string& format) {
  if (format == "json") return Ownership::json_object("dicestack leaderboard (json)", kLeaderboardFormat, {"rows", "dicestack_version"});
  if (format == "csv") return Ownership::first_line("dicestack leaderboard (csv)", {kCsvHeader, kCsvHeaderV1});
  // md and latex: our marker line, or the header line tables had before the marker.
  const std::string marker = file_marker(format), what = "dicestack leaderboard (" + format + ")";
  return {what, [marker = marker.substr(0, marker.size() - 1), format](const std::filesystem::path& p) {
            std::ifstream in(p, std::ios::binary);
            std::string first;
            std::getline(in, first);
            const std::string old = format == "latex" ? "% dicestack " : "dicestack ";
            return first == marker || (first.rfind(old, 0) == 0 && first.find(" leaderboard: ") != std::string::npos);
          }};
}

Ownership partial_ownership() {
  return Ownership::json_object("dicestack leaderboard progress file", kPartialFormat, {"meta", "rows"});
}

std::string render(const std::vector<Row>& rows, const std::string& format, const std::string& header, const json& meta) {
  std::ostringstream os;
  const std::vector<std::string> cols{"regressor", "learner", "features", "train error", "test error", "dice in cup",
                                      "stacked", "wall contact", "realistic success", "fit s", "us/step"};
  auto cells = [](const Row& r) {
    return std::vector<std::string>{r.regressor, r.learner, r.features, fixed(r.train_error, 3), fixed(r.test_error, 3),
                                    fixed(r.dice_in_cup, 2), pct(r.stacked, r.episodes), pct(r.walls, r.episodes),
                                    pct(r.success, r.episodes), fixed(r.fit_s, 2), fixed(r.us_per_step, 1)};
  };
  if (format == "json") {
    json j = meta;
    j["format"] = kLeaderboardFormat;
    j["version"] = 1;
    j["rows"] = json::array();
    for (const auto& r : rows) j["rows"].push_back(row_json(r));
    os << j.dump(2) << '\n';
  } else if (format == "csv") {
    os << kCsvHeader << '\n';
    for (const auto& r : rows) {
      const Rate st = wilson(r.stacked, r.episodes), wc = wilson(r.walls, r.episodes), rs = wilson(r.success, r.episodes);
      os << r.regressor << ',' << r.learner << ',' << r.features << ',' << r.train_error << ',' << r.test_error << ',' << r.dice_in_cup << ','
         << st.value << ',' << st.low << ',' << st.high << ',' << wc.value << ',' << rs.value << ',' << rs.low << ','
         << rs.high << ',' << r.episodes << ',' << r.fit_s << ',' << r.us_per_step << '\n';
    }
  } else if (format == "latex") {
    os << "% " << header << "\n\\begin{tabular}{lllrrrrrrrr}\n\\hline\n";
    for (std::size_t c = 0; c < cols.size(); ++c) os << cols[c] << (c + 1 < cols.size() ? " & " : " \\\\\n\\hline\n");
    for (const auto& r : rows) {
      const auto v = cells(r);
      for (std::size_t c = 0; c < v.size(); ++c) {
        std::string cell = v[c];
        for (std::size_t p = 0; (p = cell.find_first_of("%_", p)) != std::string::npos; p += 2) cell.insert(p, "\\");
        os << cell << (c + 1 < v.size() ? " & " : " \\\\\n");
      }
    }
    os << "\\hline\n\\end{tabular}\n";
  } else {
    os << header << "\n\n|";
    for (const auto& c : cols) os << ' ' << c << " |";
    os << "\n|";
    for (std::size_t c = 0; c < cols.size(); ++c) os << (c < 3 ? "---|" : "---:|");
    os << '\n';
    for (const auto& r : rows) {
      os << '|';
      for (const auto& v : cells(r)) os << ' ' << v << " |";
      os << '\n';
    }
  }
  return os.str();
}

int run_leaderboard(LeaderboardOptions opt) {
  const WorldConfig world = opt.world.load();
  const bool paper = opt.profile == "paper";
  const int episodes = opt.episodes > 0 ? opt.episodes : (paper ? 100 : 20);
  const auto dir = opt.demos.resolve(world);
  const DemoSet set = read_demo_set(dir);
  const auto regressors = opt.regressors.empty() ? RegressorRegistry::global().names() : opt.regressors;
  const auto learners = opt.learners.empty() ? std::vector<std::string>{"bc", "dagger", "dart"} : opt.learners;
  // Learner options: the profile's defaults, then --option (for every learner that has the key).
  auto options_for = [&](const std::string& learner) {
    std::vector<std::string> out;
    if (learner == "dagger") out = paper ? std::vector<std::string>{"iterations=5", "rollouts=20"}
                                         : std::vector<std::string>{"iterations=2", "rollouts=10"};
    if (learner == "dad" && !paper) out = {"windows=2", "iterations=1", "corrector_iterations=10"};  // paper: its defaults
    for (const auto& kv : opt.options) {
      const auto key = kv.substr(0, kv.find('='));
      for (const auto& p : LearnerRegistry::global().info(learner).params)
        if (p.name == key) {
          std::erase_if(out, [&](const std::string& o) { return o.substr(0, o.find('=')) == key; });
          out.push_back(kv);
        }
    }
    return out;
  };
  for (const auto& r : regressors) RegressorRegistry::global().info(r);  // fail fast on typos
  std::vector<std::string> known_baselines = optimiser_names();
  known_baselines.insert(known_baselines.end(), {"reinforce", "rrt"});
  if (opt.baselines.size() == 1 && opt.baselines[0] == "all") opt.baselines = known_baselines;
  for (const auto& b : opt.baselines)
    if (std::find(known_baselines.begin(), known_baselines.end(), b) == known_baselines.end())
      throw ConfigError("unknown baseline \"" + b + "\"; expected cmaes, de, basinhop, bayes, reinforce, rrt or all");
  for (const auto& l : learners)
    if (LearnerRegistry::global().info(l).needs_trajectories && opt.split == "rows")
      throw ConfigError("learner \"" + l + "\" learns from whole demonstrations; --split rows shuffles their rows: use --split episodes");

  // (learner, feature map) rows: each learner with every map of --features it can read, or with
  // its own default map.
  std::vector<std::pair<std::string, std::string>> combos;
  for (const auto& l : learners) {
    const LearnerInfo& info = LearnerRegistry::global().info(l);
    // The paper profile's full picture: every learner with the bare state and with dart's map too.
    std::vector<std::string> maps{info.default_features};
    if (paper && info.default_features != "state") maps.insert(maps.begin(), "state");
    if (paper && info.default_features == "state") maps.push_back(LearnerRegistry::global().info("dart").default_features);
    for (const auto& f : opt.features.empty() ? maps : opt.features) {
      feature_map(f);  // unknown names fail before any work
      if (info.state_features_only && f != "state") {
        if (!opt.features.empty()) print_progress("note: " + l + " reads only the state; skipping features " + f);
        continue;
      }
      if (opt.split == "rows" && f != "state" && opt.features.empty()) continue;  // a default map that needs episodes
      if (opt.split == "rows" && f != "state")
        throw ConfigError("features \"" + f + "\" read an episode's history; --split rows shuffles the rows: use --split episodes");
      combos.emplace_back(l, f);
    }
  }

  // Episode split: learners get the training episodes. Row split (the paper's protocol): they
  // get the training rows as one pseudo-episode, as the paper fitted on shuffled rows.
  const Split split = opt.split == "rows" ? split_by_rows(set.episodes) : split_by_episode(set.episodes);
  std::map<std::string, Split> feature_splits;  // the same split seen through each feature map
  auto split_for = [&](const std::string& f) -> const Split& {
    if (f == "state") return split;
    if (!feature_splits.contains(f)) feature_splits.emplace(f, split_by_episode(set.episodes, feature_map(f)));
    return feature_splits.at(f);
  };
  std::vector<Episode> train, held_out;
  if (opt.split == "rows") {
    Episode rows;
    rows.name = "training-rows";
    for (Eigen::Index i = 0; i < split.train.x.rows(); ++i) {
      State st;
      Action a;
      for (std::size_t j = 0; j < kStateDim; ++j) st[j] = split.train.x(i, static_cast<Eigen::Index>(j));
      for (std::size_t j = 0; j < kActionDim; ++j) a[j] = split.train.y(i, static_cast<Eigen::Index>(j));
      rows.states.push_back(st);
      rows.actions.push_back(a);
      rows.sources.push_back(StepSource::human);
    }
    train.push_back(std::move(rows));
  } else {
    for (std::size_t i = 0; i < set.episodes.size(); ++i) (is_test_episode(i) ? held_out : train).push_back(set.episodes[i]);
  }
  const auto sigma = column_sigma(split.train.y);

  std::size_t frames = 0;
  for (const auto& e : set.episodes) frames += e.size();
  std::ostringstream header;
  header << "dicestack " DICESTACK_VERSION " leaderboard: demonstrations " << dir.string() << " (" << set.episodes.size()
         << " episodes, " << frames << " frames); split " << split.description << "; profile " << opt.profile << "; "
         << episodes << " rollouts per training seed from random starts (seed " << opt.seed << "), " << opt.seeds
         << " training seed(s); rates with 95% Wilson intervals";
  json learner_options = json::object(), row_features = json::array();
  for (const auto& l : learners) learner_options[l] = options_for(l);
  for (const auto& [l, f] : combos) row_features.push_back(l + " " + f);
  header << "; learner options " << learner_options.dump() << "; features " << row_features.dump();
  if (!paper && opt.regressors.empty() && std::find(learners.begin(), learners.end(), "dart") != learners.end())
    header << "; rbf_svr under dart left out of the quick profile (200 s to fit 60,000 rows; name it with "
              "--regressors or use --profile paper)";
  if (!opt.baselines.empty())
    header << "; baselines optimised from the paper's start with the " << opt.profile
           << " budgets, then played from the same random starts";
  const json meta{{"learner_options", learner_options}, {"features", row_features}, {"dicestack_version", DICESTACK_VERSION}, {"demos", dir.string()}, {"episodes_in_demos", set.episodes.size()},
                  {"split", split.description}, {"profile", opt.profile}, {"rollouts_per_seed", episodes},
                  {"training_seeds", opt.seeds}, {"seed", opt.seed}};

  // Resume: rows already measured with the same settings are read back.
  const std::filesystem::path partial = opt.out.empty() ? std::filesystem::path() : std::filesystem::path(opt.out.string() + ".partial.json");
  json done = json::object();
  if (!opt.out.empty()) {  // refuse a user's files before any work
    check_replaceable(opt.out, table_ownership(opt.format));
    check_replaceable(partial, partial_ownership());
  }
  if (!partial.empty() && std::filesystem::exists(partial)) {
    try {
      json p = parse_json_limited<json>(std::ifstream(partial), partial.string());
      // Rows of another version or other settings are not reused.
      if (p.value("version", json(1)) == 1 && p.value("meta", json()) == meta) done = p.value("rows", json::object());
    } catch (const std::exception&) {  // an unreadable progress file only means no rows to reuse
    }
  }

  std::vector<Row> rows;
  // The quick profile leaves out, unless asked for by name, the one row that alone would take
  // longer than the rest: a kernel SVR fitted on DART's ~60,000 rows (200 s; its rows are O(n^2)).
  auto skipped = [&](const std::string& learner, const std::string& regressor) {
    return !paper && opt.regressors.empty() && learner == "dart" && regressor == "rbf_svr";
  };
  const std::size_t total = combos.size() * regressors.size();
  std::size_t index = 0;
  for (const auto& [learner_name, features] : combos) {
    const Split& fsplit = split_for(features);
    for (const auto& name : regressors) {
      ++index;
      if (skipped(learner_name, name)) continue;
      const std::string key = learner_name + "/" + features + "/" + name;
      if (done.contains(key)) {
        rows.push_back(row_from(done[key]));
        continue;
      }
      Row row{name, learner_name, features};
      for (int s = 0; s < opt.seeds; ++s) {
        const std::uint64_t seed = opt.seed + static_cast<std::uint64_t>(s);
        print_progress("[" + std::to_string(index) + "/" + std::to_string(total) + "] " + learner_name + " " + name +
                       ": training (seed " + std::to_string(seed) + ")");
        LearnContext c;
        c.world = world;
        c.regressor = name;
        c.features = features;
        c.seed = seed;
        c.threads = opt.threads;
        c.demos = train;
        c.held_out = held_out;
        std::string last_phase;
        c.progress = [&](const Progress& p) {  // one line per iteration and phase
          const std::string phase = std::to_string(p.iteration) + p.phase;
          if (phase == last_phase) return;
          last_phase = phase;
          print_progress("[" + std::to_string(index) + "/" + std::to_string(total) + "] " + learner_name + " " + name +
                         ": training (seed " + std::to_string(seed) + "), iteration " + std::to_string(p.iteration) + "/" +
                         std::to_string(p.iterations) + ", " + p.phase);
        };
        const auto t0 = std::chrono::steady_clock::now();
        const LearnResult learned = LearnerRegistry::global().create(learner_name, options_for(learner_name))->learn(c);
        row.fit_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / opt.seeds;
        row.train_error += scaled_l1_error(fsplit.train.y, learned.model->predict(fsplit.train.x), sigma) / opt.seeds;
        if (fsplit.test.rows() == 0)
          row.test_error = -1;  // no test episode: printed "-"
        else
          row.test_error += scaled_l1_error(fsplit.test.y, learned.model->predict(fsplit.test.x), sigma) / opt.seeds;
        print_progress("[" + std::to_string(index) + "/" + std::to_string(total) + "] " + learner_name + " " + name +
                       ": " + std::to_string(episodes) + " rollouts");
        std::shared_ptr<const Model> model = learned.model;
        const EvalStats st = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, world, episodes, seed,
                                      opt.threads);
        add_outcomes(row, st, opt.seeds);
      }
      rows.push_back(row);
      if (!partial.empty()) {
        done[key] = row_json(row);
        AtomicFile f(partial, partial_ownership());
        f.stream() << json{{"format", kPartialFormat}, {"version", 1}, {"meta", meta}, {"rows", done}}.dump();
        f.commit();
      }
    }
  }
  // The baselines without demonstrations (paper V), rolled out from the same random starts.
  for (const auto& name : opt.baselines) {
    print_progress("baseline " + name);
    const auto t0 = std::chrono::steady_clock::now();
    const PolicyFactory policy = baseline_policy(name, world, paper, opt.seed, opt.threads);
    Row row{name, "baseline"};
    row.fit_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    row.train_error = row.test_error = -1;
    for (int s = 0; s < opt.seeds; ++s) {
      const EvalStats st = evaluate(policy, world, episodes, opt.seed + static_cast<std::uint64_t>(s), opt.threads);
      add_outcomes(row, st, opt.seeds);
    }
    rows.push_back(row);
  }
  // Playback of the demonstrations themselves (paper VI-A), for reference.
  print_progress("playback of the demonstrations");
  const EvalStats pb = evaluate_playback(set.episodes, world, opt.threads);
  Row playback{"(demonstrations)", "playback"};
  playback.train_error = playback.test_error = -1;
  playback.episodes = pb.episodes;
  playback.stacked = static_cast<int>(std::lround(pb.stacked.value * pb.episodes));
  playback.walls = static_cast<int>(std::lround(pb.wall_contact.value * pb.episodes));
  playback.success = static_cast<int>(std::lround(pb.realistic_success.value * pb.episodes));
  playback.dice_in_cup = pb.dice_in_cup_mean;
  rows.push_back(playback);

  const std::string table = render(rows, opt.format, header.str(), meta);
  if (opt.out.empty()) {
    std::cout << table << std::flush;
  } else {
    AtomicFile f(opt.out, table_ownership(opt.format));
    f.stream() << file_marker(opt.format) << table;
    f.commit();
    if (partial_ownership().recognises(partial)) std::filesystem::remove(partial);
    std::cout << table << "wrote " << opt.out.string() << '\n' << std::flush;
  }
  return 0;
}

}  // namespace

void add_leaderboard_command(CLI::App& app) {
  auto opt = std::make_shared<LeaderboardOptions>();
  CLI::App* cmd = app.add_subcommand("leaderboard", "Train every regressor under every learner and print Table I");
  opt->world.add_to(*cmd);
  opt->demos.add_to(*cmd);
  cmd->add_option("--regressors", opt->regressors, "Regressors (comma-separated; default: all registered)")->delimiter(',');
  cmd->add_option("--learners", opt->learners, "Learners (comma-separated; default: bc, dagger, dart)")->delimiter(',');
  cmd->add_option("--features", opt->features,
                  "Feature maps (comma-separated): a row per learner and map it can read (default: each learner's own; "
                  "paper profile: state and dart's map for every learner that reads them)")
      ->delimiter(',');
  cmd->add_option("--option", opt->options, "key=value learner option (applied to the learners that have it); repeatable");
  cmd->add_option("--baselines", opt->baselines,
                  "Baselines without demonstrations as rows of their own: cmaes, de, basinhop, bayes, reinforce, rrt "
                  "or all (quick: 1000 evaluations (bayes 200), 100 REINFORCE updates, 100 RRT nodes; paper: 5000 "
                  "(bayes 500), 1000, 1000)")
      ->delimiter(',');
  cmd->add_option("--episodes", opt->episodes, "Rollouts per row and training seed (default: 20 quick, 100 paper)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--seeds", opt->seeds, "Training seeds per row")->check(CLI::PositiveNumber)->capture_default_str();
  cmd->add_option("--seed", opt->seed, "First seed")->check(seed_check())->capture_default_str();
  cmd->add_option("--profile", opt->profile, "quick or paper")->check(CLI::IsMember({"quick", "paper"}))->capture_default_str();
  cmd->add_option("--split", opt->split, "episodes (i % 5 == 4 is test) or rows (the paper's random 25% of rows)")
      ->check(CLI::IsMember({"episodes", "rows"}))
      ->capture_default_str();
  cmd->add_option("--format", opt->format, "md, csv, latex or json")->check(CLI::IsMember({"md", "csv", "latex", "json"}))->capture_default_str();
  cmd->add_option("--out", opt->out, "Also write the table to this file (atomically)");
  cmd->add_option("--threads", opt->threads, "Threads (0 = all cores); results do not depend on it")->capture_default_str();
  cmd->callback([opt] { run_leaderboard(*opt); });
}

}  // namespace dicestack::cli
