#include <dicestack/experiments/leaderboard.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include <nlohmann/json.hpp>

#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/cluster.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/memory_budget.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/core/read_file.hpp>
#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/experiments/baseline.hpp>
#include <dicestack/learners/evaluate.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/version.hpp>

#include <dicestack/experiments/results_page.hpp>

#include "leaderboard_json.hpp"
#include "leaderboard_rows.hpp"

namespace dicestack {
namespace {

using nlohmann::json;

constexpr const char* kPartialFormat = "dicestack-leaderboard-partial";

Ownership partial_ownership() {
  return Ownership::json_object("dicestack leaderboard progress file", kPartialFormat, {"meta", "rows"});
}

}  // namespace

json leaderboard_row_object(const LeaderboardRow& r) {
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

namespace {

// A row as the progress file keeps it: the table's row, its rollouts' results, and its
// previews when the run keeps them (html).
json partial_leaderboard_row_object(const LeaderboardRow& r) {
  json j = leaderboard_row_object(r);
  json rollouts = json::array();
  for (const RowRollout& o : r.rollouts) {
    const EpisodeResult& e = o.result;
    rollouts.push_back({o.training_seed, e.index, e.seed, e.success, e.stacked, e.wall_contact, e.dice_in_cup, e.wall_step,
                        e.length, e.reward});
  }
  j["rollouts"] = std::move(rollouts);
  auto previews = [](const std::vector<RowPreview>& v) {
    json out = json::array();
    for (const RowPreview& p : v) out.push_back({{"training_seed", p.training_seed}, {"index", p.index}, {"seed", p.seed}, {"states", p.states}});
    return out;
  };
  if (!r.success_preview.empty() || !r.failure_preview.empty()) {
    j["success_preview"] = previews(r.success_preview);
    j["failure_preview"] = previews(r.failure_preview);
  }
  return j;
}

// Throws for a row the progress file does not hold whole (it is then measured again).
LeaderboardRow row_from(const json& j) {
  LeaderboardRow r;
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
  for (const json& o : j.value("rollouts", json::array())) {
    RowRollout x;
    x.training_seed = o.at(0);
    EpisodeResult& e = x.result;
    e.index = o.at(1);
    e.seed = o.at(2);
    e.success = o.at(3);
    e.stacked = o.at(4);
    e.wall_contact = o.at(5);
    e.dice_in_cup = o.at(6);
    e.wall_step = o.at(7);
    e.length = o.at(8);
    e.reward = o.at(9);
    r.rollouts.push_back(x);
  }
  auto previews = [&](const char* key) {
    std::vector<RowPreview> out;
    for (const json& p : j.value(key, json::array()))
      out.push_back({p.at("training_seed"), p.at("index"), p.at("seed"), p.at("states").get<std::vector<State>>()});
    if (out.size() > 1) throw Error(std::string("more than one ") + key);
    return out;
  };
  r.success_preview = previews("success_preview");
  r.failure_preview = previews("failure_preview");
  return r;
}

void check_one_of(const std::string& what, const std::string& value, const std::vector<std::string>& allowed) {
  if (std::find(allowed.begin(), allowed.end(), value) != allowed.end()) return;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  throw ConfigError("leaderboard: " + what + " \"" + value + "\" is not one of " + list);
}

using Say = std::function<void(const std::string& text, double fraction)>;

// What a run will do, settled before any work: every name and option checked, the rows in
// table order, and the text and settings every format carries.
struct RunPlan {
  LeaderboardRequest request;  // baselines "all" expanded
  const Profile* profile = nullptr;
  Perturbation perturbation;
  int episodes = 0;  // rollouts per training seed
  DemoSet set;
  std::vector<std::string> regressors, learners;
  std::map<std::string, LearnerSpec> specs;  // each learner row's spec ("dart:expert=tracker")
  std::vector<std::pair<std::string, std::string>> combos;  // (learner, feature map) rows
  std::string header;
  json meta;

  const std::string& base(const std::string& spec) const { return specs.at(spec).name; }

  // A learner row's options: the profile's defaults for the learner, then for the row's spec,
  // then the spec's own, then --option (for every learner that has the key).
  std::vector<std::string> options_for(const std::string& spec) const {
    const std::string& learner = base(spec);
    std::vector<std::string> out;
    auto put = [&](const std::string& kv) {
      const auto key = kv.substr(0, kv.find('='));
      for (const auto& p : LearnerRegistry::global().info(learner).params)
        if (p.name == key) {
          std::erase_if(out, [&](const std::string& o) { return o.substr(0, o.find('=')) == key; });
          out.push_back(kv);
        }
    };
    for (const auto& kv : profile->options_for(learner, spec)) put(kv);
    for (const auto& kv : specs.at(spec).options) put(kv);
    for (const auto& kv : request.options) put(kv);
    return out;
  }

  // Rows the profile leaves out unless the regressors are named (quick: rbf_svr under dart). A
  // pair names a learner row by its spec ("dart:expert=tracker") or every row of a learner ("dart").
  bool left_out(const std::string& learner, const std::string& regressor) const {
    if (!request.regressors.empty()) return false;  // named regressors are always run
    return std::any_of(profile->left_out.begin(), profile->left_out.end(), [&](const auto& pair) {
      return pair.second == regressor && (pair.first == learner || pair.first == base(learner));
    });
  }

  static std::string row_key(const std::string& learner, const std::string& features, const std::string& regressor) {
    return learner + "/" + features + "/" + regressor;
  }
};

// Every name, option and count of the request, checked against its registry or schema.
void check_request(RunPlan& plan) {
  LeaderboardRequest& opt = plan.request;
  check_one_of("split", opt.split, {"episodes", "rows"});
  leaderboard_format(opt.format);
  if (opt.episodes < 0) throw ConfigError("leaderboard: episodes must be positive (0: the profile's), got " + std::to_string(opt.episodes));
  if (opt.seeds < 1) throw ConfigError("leaderboard: seeds must be at least 1, got " + std::to_string(opt.seeds));
  for (const auto& l : plan.learners) plan.specs.emplace(l, parse_learner_spec(l));  // unknown names fail before any work
  // Every option parsed against its learner's schema before any work (a bad value would
  // otherwise surface when that row's turn to train came, after the rows before it), and an
  // --option no learner of this run has is a typo, not a no-op.
  for (const auto& l : plan.learners) {
    const auto& schema = LearnerRegistry::global().info(plan.base(l)).params;
    const Params params(schema, plan.options_for(l), l);
    if (std::any_of(schema.begin(), schema.end(), [](const ParamSpec& p) { return p.name == "perturb"; }))
      learner_perturbation(params, opt.world, l);  // a level or a file, checked against the world
  }
  for (const auto& kv : opt.options) {
    const auto key = kv.substr(0, kv.find('='));
    const bool used = std::any_of(plan.learners.begin(), plan.learners.end(), [&](const std::string& l) {
      const auto& params = LearnerRegistry::global().info(plan.base(l)).params;
      return std::any_of(params.begin(), params.end(), [&](const ParamSpec& p) { return p.name == key; });
    });
    if (!used) {
      std::string names;
      for (const auto& l : plan.learners) names += (names.empty() ? "" : ", ") + l;
      throw ConfigError("--option " + kv + ": none of this leaderboard's learners (" + names + ") has an option \"" + key +
                        "\" (`dicestack learners` lists each one's)");
    }
  }
  for (const auto& r : plan.regressors) RegressorRegistry::global().info(r);  // fail fast on typos
  if (opt.baselines.size() == 1 && opt.baselines[0] == "all") opt.baselines = baseline_names();
  for (const auto& b : opt.baselines) baseline(b);  // unknown names fail before any work
  if (opt.controller == ActionKind::joint_torque && opt.split == "rows")
    throw ConfigError("leaderboard --controller joint_torque: --split rows shuffles rows of the state map, which answers the "
                      "cup's actions; use --split episodes");
  if (opt.controller == ActionKind::joint_torque && !opt.baselines.empty())
    throw ConfigError("leaderboard --controller joint_torque: the baselines act in the cup's actions; leave --baselines out");
  for (const auto& l : plan.learners)
    if (LearnerRegistry::global().info(plan.base(l)).needs_trajectories && opt.split == "rows")
      throw ConfigError("learner \"" + l + "\" learns from whole demonstrations; --split rows shuffles their rows: use --split episodes");
}

// The (learner, feature map) rows: each learner with every map of --features it can read, or
// with its own default map.
std::vector<std::pair<std::string, std::string>> row_combos(const RunPlan& plan, const Say& say) {
  const LeaderboardRequest& opt = plan.request;
  std::vector<std::pair<std::string, std::string>> combos;
  for (const auto& l : plan.learners) {
    const LearnerInfo& info = LearnerRegistry::global().info(plan.base(l));
    // The paper profile's full picture: every learner with the bare state and with dart's map too
    // (cup maps: in torques, each learner's own).
    const bool torques = opt.controller == ActionKind::joint_torque;
    const std::string cup_map = default_features(plan.base(l), plan.options_for(l));
    const std::string own = torques ? torque_map_name(cup_map) : cup_map;
    std::vector<std::string> maps{own};
    if (plan.profile->every_feature_map && !torques && own != "state") maps.insert(maps.begin(), "state");
    if (plan.profile->every_feature_map && !torques && own == "state") maps.push_back(LearnerRegistry::global().info("dart").default_features);
    for (const auto& f : opt.features.empty() ? maps : opt.features) {
      if ((feature_map(f).action_kind() == ActionKind::joint_torque) != torques)  // unknown names fail here too
        throw ConfigError("feature map \"" + f + "\" answers " + std::string(action_kind_name(feature_map(f).action_kind())) +
                          " actions, not the --controller " + std::string(action_kind_name(opt.controller)) + " ones");
      if (info.own_features_only && f != own) {
        if (!opt.features.empty()) say("note: " + l + " reads only its own map (" + own + ") here; skipping features " + f, 0.0);
        continue;
      }
      if (opt.split == "rows" && f != "state" && opt.features.empty()) continue;  // a default map that needs episodes
      if (opt.split == "rows" && f != "state")
        throw ConfigError("features \"" + f + "\" read an episode's history; --split rows shuffles the rows: use --split episodes");
      require_labellable(info.params, Params(info.params, plan.options_for(l), l), opt.world, feature_map(f), plan.base(l));
      combos.emplace_back(l, f);
    }
  }
  return combos;
}

// A bc row in joint torques fits the set's own actions: they must be torques, with the links
// they were read with (dart and dagger take theirs from their experts). Checked before any row.
void require_torque_episodes(const RunPlan& plan) {
  for (const auto& [learner, features] : plan.combos) {
    if (plan.base(learner) != "bc" || feature_map(features).action_kind() != ActionKind::joint_torque) continue;
    try {
      for (const Episode& e : plan.set.episodes) check_rows_of(e, feature_map(features));
    } catch (const InputError& e) {
      throw ConfigError("leaderboard: " + learner + " fits the joint torques of the episodes of " + plan.request.demos.string() +
                        ": " + e.what() + "; or leave it out (--learners dart:expert=tracker)");
    }
  }
}

// The header line and the settings (meta) every format carries; a progress file is reused only
// with the same meta.
void describe_run(RunPlan& plan, const DemoSplit& split) {
  const LeaderboardRequest& opt = plan.request;
  std::size_t frames = 0;
  for (const auto& e : plan.set.episodes) frames += e.size();
  std::ostringstream header;
  header << "dicestack " DICESTACK_VERSION " leaderboard: demonstrations " << opt.demos.string() << " ("
         << plan.set.episodes.size() << " episodes, " << frames << " frames); split " << split.description()
         << "; profile " << opt.profile << "; " << plan.episodes << " rollouts per training seed from " << start_distribution_name(opt.world) << " starts (seed "
         << opt.seed << "), " << opt.seeds << " training seed(s); rates with 95% Wilson intervals"
         << (opt.controller == ActionKind::joint_torque ? "; actions in joint torques" : "");
  json learner_options = json::object(), row_features = json::array();
  for (const auto& l : plan.learners) learner_options[l] = plan.options_for(l);
  for (const auto& [l, f] : plan.combos) row_features.push_back(l + " " + f);
  header << "; learner options " << learner_options.dump() << "; features " << row_features.dump();
  if (std::any_of(plan.learners.begin(), plan.learners.end(), [&](const std::string& l) {
        return std::any_of(plan.regressors.begin(), plan.regressors.end(), [&](const std::string& r) { return plan.left_out(l, r); });
      }))
    header << "; " << plan.profile->left_out_note;
  if (!plan.perturbation.nominal())
    header << "; rollouts in perturbed worlds (" << opt.perturb << ": " << perturbation_summary(plan.perturbation)
           << "), drawn per episode; training nominal";
  if (!opt.estimator.empty() && opt.estimator != "none" && senses(plan.perturbation))
    header << "; the policies see the " << opt.estimator << " estimator's estimate";
  if (!opt.baselines.empty())
    header << "; baselines optimised from the paper's start with the " << opt.profile
           << " budgets, then played from the same random starts";
  plan.header = header.str();
  plan.meta = {{"learner_options", learner_options}, {"features", row_features}, {"dicestack_version", DICESTACK_VERSION},
               {"demos", opt.demos.string()}, {"episodes_in_demos", plan.set.episodes.size()},
               {"split", split.description()}, {"profile", opt.profile}, {"rollouts_per_seed", plan.episodes},
               {"training_seeds", opt.seeds}, {"seed", opt.seed}};
  // Only a perturbed run names its perturbation: a nominal table and its progress file stay as they were.
  if (!plan.perturbation.nominal()) plan.meta["perturb"] = json::parse(perturbation_to_json(plan.perturbation));
  if (!opt.estimator.empty() && opt.estimator != "none" && senses(plan.perturbation)) plan.meta["estimator"] = opt.estimator;
  if (start_distribution_name(opt.world) != "random") plan.meta["start"] = start_distribution_name(opt.world);
  if (opt.controller != ActionKind::cup) plan.meta["controller"] = action_kind_name(opt.controller);
  if (opt.world.embodiment == Embodiment::arm) plan.meta["embodiment"] = "arm";  // a cup's progress files stay as they were
}

// Resume: the rows of <out>.partial.json measured with the same settings, read by the root
// (which alone writes the file) and given to every rank. A row not held whole is left out (it
// is measured again); an unreadable file only means no rows to reuse.
json rows_already_measured(Cluster& cluster, const std::filesystem::path& partial, const json& meta) {
  return json::parse(on_root(cluster, [&] {
    json rows_done = json::object();
    if (partial.empty() || !std::filesystem::exists(partial)) return rows_done.dump();
    try {
      json p = parse_json_limited<json>(read_file(partial), partial.string());
      // Rows of another version or other settings are not reused.
      if (p.value("version", json(1)) == 1 && p.value("meta", json()) == meta) rows_done = p.value("rows", json::object());
      if (!rows_done.is_object()) rows_done = json::object();
      for (auto it = rows_done.begin(); it != rows_done.end();) {
        try {
          row_from(*it);
          ++it;
        } catch (const std::exception&) {
          it = rows_done.erase(it);
        }
      }
    } catch (const std::exception&) {
    }
    return rows_done.dump();
  }));
}

// One unit of the run: a training seed of a learner row, or a baseline whole (its seeds share
// one optimisation).
struct Job {
  std::size_t index = 0;  // 1-based place among the learner rows; 0 for a baseline
  std::string learner, features, regressor, key;
  int seed = 0;  // which training seed of the row (learner rows)
  std::size_t baseline = 0;
};

// The work still to do, in table order: each learner row not left out nor already measured,
// once per training seed, then each baseline.
std::vector<Job> pending_jobs(const RunPlan& plan, const json& done) {
  std::vector<Job> jobs;
  std::size_t index = 0;
  for (const auto& [learner, features] : plan.combos)
    for (const auto& name : plan.regressors) {
      ++index;
      const std::string key = RunPlan::row_key(learner, features, name);
      if (!plan.left_out(learner, name) && !done.contains(key))
        for (int s = 0; s < plan.request.seeds; ++s) jobs.push_back({index, learner, features, name, key, s, 0});
    }
  for (std::size_t b = 0; b < plan.request.baselines.size(); ++b)
    jobs.push_back({0, "baseline", "-", plan.request.baselines[b], "", 0, b});
  return jobs;
}

// The deal over several ranks, on one line: which rank runs each job, and each rank's estimated load.
std::string deal_text(const std::vector<double>& cost, int ranks) {
  const std::vector<int> owner = deal_items(cost.size(), ranks, cost);
  std::vector<double> load(static_cast<std::size_t>(ranks), 0.0);
  std::string ranks_of;
  for (std::size_t j = 0; j < cost.size(); ++j) {
    load[static_cast<std::size_t>(owner[j])] += cost[j];
    ranks_of += (j ? " " : "") + std::to_string(owner[j]);
  }
  std::string loads;
  for (double l : load) loads += (loads.empty() ? "" : " ") + std::to_string(static_cast<long>(std::lround(l)));
  return "deal: " + std::to_string(cost.size()) + " jobs on " + std::to_string(ranks) + " ranks, estimated seconds per rank " +
         loads + "; rank of each job in table order: " + ranks_of;
}

// Runs the jobs (over the ranks when there are several: deal_jobs, longest first by
// estimated_row_cost) and returns each job's row, by the job that starts it: a learner row at
// its first seed's job, once the root has all its seeds. The root writes each finished learner
// row to `partial` (when not empty) as it completes.
std::vector<std::optional<LeaderboardRow>> measure_jobs(const RunPlan& plan, const std::vector<Job>& jobs,
                                                        const RowRunner& runner, json& done,
                                                        const std::filesystem::path& partial, const Say& say,
                                                        std::atomic<const std::function<void()>*>& poll) {
  const LeaderboardRequest& opt = plan.request;
  Cluster& cluster = *opt.cluster;
  std::vector<std::optional<LeaderboardRow>> measured(jobs.size());
  std::vector<std::optional<SeedResult>> seed_results(jobs.size());
  std::size_t finished = 0;
  auto keep_row = [&](std::size_t j, LeaderboardRow row) {
    if (!jobs[j].key.empty() && !partial.empty() && cluster.is_root()) {
      done[jobs[j].key] = partial_leaderboard_row_object(row);
      AtomicFile f(partial, partial_ownership());
      f.stream() << json{{"format", kPartialFormat}, {"version", 1}, {"meta", plan.meta}, {"rows", done}}.dump();
      f.commit();
    }
    measured[j] = std::move(row);
  };
  // Job j's result (a packed SeedResult or baseline row) has arrived.
  auto store = [&](std::size_t j, const std::string& bytes) {
    ++finished;
    if (jobs[j].index == 0) {
      Unpacker u(bytes, "leaderboard baseline row");
      keep_row(j, unpack_row(u));
      return;
    }
    seed_results[j] = unpack_seed_result(bytes);
    const std::size_t first = j - static_cast<std::size_t>(jobs[j].seed);
    std::vector<SeedResult> seeds;
    for (std::size_t k = first; k < first + static_cast<std::size_t>(opt.seeds); ++k) {
      if (!seed_results[k]) return;  // more seeds to come
      seeds.push_back(*seed_results[k]);
    }
    keep_row(first, runner.combine(jobs[first].learner, jobs[first].features, jobs[first].regressor, seeds));
  };
  auto keep = [&](std::size_t j, const std::string& bytes, int rank) {
    store(j, bytes);
    if (cluster.size() > 1 && cluster.is_root() && rank != cluster.rank())
      say((jobs[j].index ? jobs[j].learner + " " + jobs[j].features + " " + jobs[j].regressor + " (seed " +
                               std::to_string(opt.seed + static_cast<std::uint64_t>(jobs[j].seed)) + ")"
                         : "baseline " + jobs[j].regressor) +
              " finished on rank " + std::to_string(rank),
          static_cast<double>(finished) / (static_cast<double>(jobs.size()) + 0.5));
  };
  // Progress in units of rows (one per learner row and per baseline) on one process; in units
  // of jobs finished over several ranks, where they finish out of order.
  const std::size_t learner_rows = plan.combos.size() * plan.regressors.size();
  const double row_units = static_cast<double>(learner_rows + opt.baselines.size()) + 0.5;
  const double job_units = static_cast<double>(jobs.size()) + 0.5;
  auto run = [&](std::size_t j, const std::function<void()>& poll_now) {
    const Job& job = jobs[j];
    double from = static_cast<double>(finished) / job_units, span = 1.0 / job_units;
    if (cluster.size() == 1) {
      from = (job.index ? static_cast<double>(job.index - 1) + static_cast<double>(job.seed) / opt.seeds
                        : static_cast<double>(learner_rows + job.baseline)) / row_units;
      span = (job.index ? 1.0 / opt.seeds : 1.0) / row_units;
    }
    poll = &poll_now;  // the root takes other ranks' results while it reports its own job's progress
    struct Unset {
      std::atomic<const std::function<void()>*>& poll;
      ~Unset() { poll = nullptr; }
    } unset{poll};
    Cluster& inner = local_cluster();  // a job runs whole on its rank
    if (job.index == 0) {
      Packer p;
      pack_row(p, runner.baseline_row(job.regressor, inner, from, span));
      return p.take();
    }
    const std::string row_text = "[" + std::to_string(job.index) + "/" + std::to_string(learner_rows) + "] " + job.learner + " " + job.regressor;
    return pack_seed_result(runner.learner_seed(job.learner, job.features, job.regressor, job.seed, row_text, inner, from, span));
  };
  std::vector<double> cost(jobs.size());
  for (std::size_t j = 0; j < jobs.size(); ++j)
    cost[j] = estimated_row_cost(jobs[j].index ? plan.base(jobs[j].learner) : "baseline", jobs[j].regressor, jobs[j].features,
                                 *plan.profile, jobs[j].index ? plan.episodes : plan.episodes * opt.seeds);
  if (cluster.size() > 1) say(deal_text(cost, cluster.size()), 0.0);
  deal_jobs(cluster, cost, run, keep);
  return measured;
}

// The table in its order: learner rows (measured now or read back), then the baselines.
std::vector<LeaderboardRow> table_rows(const RunPlan& plan, const std::vector<Job>& jobs,
                                       std::vector<std::optional<LeaderboardRow>>& measured, const json& done) {
  std::vector<LeaderboardRow> rows;
  std::size_t next = 0, index = 0;
  for (const auto& [learner, features] : plan.combos)
    for (const auto& name : plan.regressors) {
      ++index;
      if (plan.left_out(learner, name)) continue;
      if (next < jobs.size() && jobs[next].index == index) {
        rows.push_back(std::move(*measured[next]));
        next += static_cast<std::size_t>(plan.request.seeds);
      } else {
        rows.push_back(row_from(done.at(RunPlan::row_key(learner, features, name))));
      }
    }
  for (; next < jobs.size(); ++next) rows.push_back(std::move(*measured[next]));
  return rows;
}

// Playback of the demonstrations themselves (paper VI-A), for reference.
LeaderboardRow playback_row(const RunPlan& plan) {
  const EvalStats pb = evaluate_playback(plan.set.episodes, plan.request.world, plan.request.threads, *plan.request.cluster);
  LeaderboardRow playback{"(demonstrations)", "playback"};
  playback.train_error = playback.test_error = -1;
  add_outcomes(playback, pb, 1);
  playback.us_per_step = 0;  // playback reads recorded actions: no policy time to report
  return playback;
}

}  // namespace

Leaderboard run_leaderboard(const LeaderboardRequest& request, const LeaderboardProgressFn& progress) {
  // Where the root stands in its own job's progress, other ranks' results are taken (deal_jobs).
  std::atomic<const std::function<void()>*> poll{nullptr};  // read from the job's worker threads
  const RowReport report = [&](const std::string& text, double fraction, bool milestone) {
    if (progress) progress({text, std::clamp(fraction, 0.0, 1.0), milestone});
    if (const auto* p = poll.load()) (*p)();
  };
  const Say say = [&](const std::string& text, double fraction) { report(text, fraction, true); };

  RunPlan plan;
  plan.request = request;
  const LeaderboardRequest& opt = plan.request;
  plan.profile = &leaderboard_profile(opt.profile);
  plan.episodes = opt.episodes > 0 ? opt.episodes : plan.profile->rollouts;
  plan.regressors = opt.regressors.empty() ? RegressorRegistry::global().names() : opt.regressors;
  // In joint torques bc and dagger's default (include_demos) would fit the recordings' cup actions.
  const std::vector<std::string> torque_learners{"dart:expert=tracker"};
  plan.learners = !opt.learners.empty() ? opt.learners : opt.controller == ActionKind::joint_torque ? torque_learners : plan.profile->learners;
  check_request(plan);
  plan.perturbation = load_perturbation(opt.perturb, opt.world);  // before any work
  if (!opt.estimator.empty()) estimator_config(opt.estimator);  // a bad name, before any work
  {
    EvalRequest rollouts;
    rollouts.episodes = plan.episodes;
    rollouts.threads = opt.threads;
    rollouts.perturbation = plan.perturbation;
    rollouts.actions = opt.controller;
    if (!opt.estimator.empty()) rollouts.estimator = estimator_config(opt.estimator);
    check_evaluation(opt.world, rollouts);
  }
  plan.combos = row_combos(plan, say);  // a row that cannot train is refused before the demonstrations are read
  plan.set = read_demo_set(opt.demos);
  require_torque_episodes(plan);
  for (const auto& [learner, features] : plan.combos) check_map_world(feature_map(features), opt.world);
  // The table keeps every row's rollouts of every seed (the pages' per-episode results).
  const double rollouts = static_cast<double>(plan.combos.size()) * opt.seeds * plan.episodes;
  require_memory("leaderboard", static_cast<std::uint64_t>(std::min(rollouts, 1e18)),
                 episode_memory_bound(opt.world.episode.max_steps), "rollouts (rows x seeds x episodes)");
  // Episode split: learners get the training episodes. Row split (the paper's protocol): they
  // get the training rows as one pseudo-episode, as the paper fitted on shuffled rows.
  const DemoSplit split(plan.set.episodes, opt.split);
  describe_run(plan, split);

  const LeaderboardFormat& format = leaderboard_format(opt.format);
  const std::filesystem::path partial = opt.out.empty() ? std::filesystem::path() : std::filesystem::path(opt.out.string() + ".partial.json");
  if (!opt.out.empty()) {  // refuse a user's files before any work
    check_replaceable(opt.out, format.ownership());
    check_replaceable(partial, partial_ownership());
    if (format.check_beside) format.check_beside(opt.out);
  }
  json done = rows_already_measured(*opt.cluster, partial, plan.meta);
  const std::vector<Job> jobs = pending_jobs(plan, done);

  RowSettings settings;
  settings.world = opt.world;
  settings.profile = plan.profile;
  settings.split = &split;
  settings.episodes = plan.episodes;
  settings.seeds = opt.seeds;
  settings.seed = opt.seed;
  settings.threads = opt.threads;
  settings.perturbation = plan.perturbation;
  settings.estimator = opt.estimator;
  settings.previews = opt.format == "html";
  settings.learner_options = [&plan](const std::string& spec) { return plan.options_for(spec); };
  const RowRunner runner(settings, report);
  auto measured = measure_jobs(plan, jobs, runner, done, partial, say, poll);

  Leaderboard board;
  board.rows = table_rows(plan, jobs, measured, done);
  const double units = static_cast<double>(plan.combos.size() * plan.regressors.size() + opt.baselines.size()) + 0.5;
  say("playback of the demonstrations", (units - 0.5) / units);
  board.rows.push_back(playback_row(plan));
  board.header = plan.header;
  board.meta_json = plan.meta.dump();
  board.world = opt.world;
  board.demos_description = plan.set.description;
  return board;
}

std::string render_leaderboard(const Leaderboard& board, const std::string& format) {
  return leaderboard_format(format).render(board, {});
}

std::string leaderboard_row_json(const LeaderboardRow& row) { return leaderboard_row_object(row).dump(); }

void write_leaderboard(const Leaderboard& board, const std::string& format_name, const std::filesystem::path& out) {
  const LeaderboardFormat& format = leaderboard_format(format_name);
  if (format.write) {
    format.write(board, out);
  } else {
    const std::string table = format.render(board, out);
    AtomicFile f(out, format.ownership());
    f.stream() << format.marker << table;
    f.commit();
  }
  const std::filesystem::path partial = out.string() + ".partial.json";
  if (partial_ownership().recognises(partial)) std::filesystem::remove(partial);
}

}  // namespace dicestack
