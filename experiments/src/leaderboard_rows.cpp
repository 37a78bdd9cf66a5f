#include "leaderboard_rows.hpp"

#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include <dicestack/core/error.hpp>
#include <dicestack/experiments/baseline.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/regressors/score.hpp>

namespace dicestack {

namespace {

void pack_previews(Packer& p, const std::vector<RowPreview>& previews) {
  p.put<std::uint64_t>(previews.size());
  for (const RowPreview& v : previews) p.put(v.training_seed).put(v.index).put(v.seed).put_vector(v.states);
}

std::vector<RowPreview> unpack_previews(Unpacker& u) {
  const auto n = u.get<std::uint64_t>();
  if (n > 1) throw Error("leaderboard row: " + std::to_string(n) + " previews of one kind (at most 1)");
  std::vector<RowPreview> out(static_cast<std::size_t>(n));
  for (RowPreview& v : out) {
    v.training_seed = u.get<std::uint64_t>();
    v.index = u.get<int>();
    v.seed = u.get<std::uint64_t>();
    v.states = u.get_vector<State>();
  }
  return out;
}

}  // namespace

std::string pack_seed_result(const SeedResult& r) {
  Packer p;
  p.put(r.fit_s).put(r.train_error).put(r.test_error).put<std::uint8_t>(r.has_test).put(r.stats).put_vector(r.results);
  pack_previews(p, r.success_preview);
  pack_previews(p, r.failure_preview);
  return p.take();
}

SeedResult unpack_seed_result(std::string_view bytes) {
  Unpacker u(bytes, "leaderboard seed result");
  SeedResult r;
  r.fit_s = u.get<double>();
  r.train_error = u.get<double>();
  r.test_error = u.get<double>();
  r.has_test = u.get<std::uint8_t>() != 0;
  r.stats = u.get<EvalStats>();
  r.results = u.get_vector<EpisodeResult>();
  r.success_preview = unpack_previews(u);
  r.failure_preview = unpack_previews(u);
  return r;
}

void pack_row(Packer& p, const LeaderboardRow& r) {
  p.put_string(r.regressor).put_string(r.learner).put_string(r.features);
  p.put(r.train_error).put(r.test_error).put(r.fit_s).put(r.us_per_step).put(r.dice_in_cup);
  p.put(r.episodes).put(r.stacked).put(r.walls).put(r.success);
  p.put_vector(r.rollouts);
  pack_previews(p, r.success_preview);
  pack_previews(p, r.failure_preview);
}

LeaderboardRow unpack_row(Unpacker& u) {
  LeaderboardRow r;
  r.regressor = u.get_string();
  r.learner = u.get_string();
  r.features = u.get_string();
  r.train_error = u.get<double>();
  r.test_error = u.get<double>();
  r.fit_s = u.get<double>();
  r.us_per_step = u.get<double>();
  r.dice_in_cup = u.get<double>();
  r.episodes = u.get<int>();
  r.stacked = u.get<int>();
  r.walls = u.get<int>();
  r.success = u.get<int>();
  r.rollouts = u.get_vector<RowRollout>();
  r.success_preview = unpack_previews(u);
  r.failure_preview = unpack_previews(u);
  return r;
}

void add_outcomes(LeaderboardRow& row, const EvalStats& st, int seeds) {
  const OutcomeCounts n = outcome_counts(st);
  row.episodes += n.episodes;
  row.stacked += n.stacked;
  row.walls += n.wall_contact;
  row.success += n.realistic_success;
  row.dice_in_cup += st.dice_in_cup_mean / seeds;
  row.us_per_step += st.policy_us_per_step / seeds;
}

void add_rollouts(LeaderboardRow& row, std::uint64_t training_seed, const std::vector<EpisodeResult>& results,
                  const std::vector<RowPreview>& success, const std::vector<RowPreview>& failure) {
  for (const EpisodeResult& r : results) row.rollouts.push_back({training_seed, r});
  if (row.success_preview.empty()) row.success_preview = success;
  if (row.failure_preview.empty()) row.failure_preview = failure;
}

void keep_rollouts(EvalRequest& request, bool previews, std::vector<EpisodeResult>& results, std::vector<Episode>& episodes) {
  request.results = &results;
  request.rollouts = previews ? &episodes : nullptr;
}

void pick_previews(const std::vector<Episode>& episodes, std::uint64_t training_seed, std::vector<RowPreview>& success,
                   std::vector<RowPreview>& failure) {
  for (std::size_t i = 0; i < episodes.size(); ++i) {
    const Episode& e = episodes[i];
    std::vector<RowPreview>& into = e.outcome.realistic_success() ? success : failure;
    if (!into.empty()) continue;
    RowPreview v{training_seed, static_cast<int>(i), e.seed, e.states};
    if (e.final_state) v.states.push_back(*e.final_state);
    into.push_back(std::move(v));
  }
}

SeedResult RowRunner::learner_seed(const std::string& learner, const std::string& features, const std::string& regressor,
                                   int seed_index, const std::string& row_text, Cluster& inner, double from,
                                   double span) const {
  const std::uint64_t seed = s_.seed + static_cast<std::uint64_t>(seed_index);
  // Training is the first half of a seed's share, rollouts the second.
  auto at = [&](double part) { return from + span * part; };
  report_(row_text + ": training (seed " + std::to_string(seed) + ")", at(0.0), true);
  LearnContext c;
  c.world = s_.world;
  c.regressor = regressor;
  c.features = features;
  c.seed = seed;
  c.threads = s_.threads;
  c.demos = s_.split->train();
  c.held_out = s_.split->held_out();
  c.cluster = &inner;
  std::string last_phase;
  c.progress = [&](const Progress& p) {  // a milestone per iteration and phase
    const std::string phase = std::to_string(p.iteration) + p.phase;
    const std::string iteration =
        p.iterations > 0 ? "iteration " + std::to_string(p.iteration) + "/" + std::to_string(p.iterations) + ", " : "";
    const std::string text = row_text + ": training (seed " + std::to_string(seed) + "), " + iteration + p.phase;
    report_(text, at(0.5 * p.fraction), phase != last_phase);
    last_phase = phase;
  };
  SeedResult r;
  const auto t0 = std::chrono::steady_clock::now();
  const LearnResult learned =
      LearnerRegistry::global().create(parse_learner_spec(learner).name, s_.learner_options(learner))->learn(c);
  r.fit_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // A map of the arm's links or torques has no error on recordings of the cup (as `train`).
  const FeatureMap& map = learned.model->features();
  if (!map.reads_links() && map.action_kind() == ActionKind::cup) {
    const Score errors = score(*learned.model, *s_.split);
    r.train_error = errors.train_error;
    r.has_test = errors.test_error.has_value();
    r.test_error = errors.test_error.value_or(0.0);
  } else {
    r.train_error = -1;  // printed "-"
  }
  const std::string rollouts_text = row_text + ": " + std::to_string(s_.episodes) + " rollouts";
  report_(rollouts_text, at(0.5), true);
  std::shared_ptr<const Model> model = learned.model;
  EvalRequest request;
  request.episodes = s_.episodes;
  request.seed = seed;
  request.threads = s_.threads;
  request.perturbation = s_.perturbation;
  request.estimator = estimator_config(estimator_for(s_.estimator, *model));
  request.actions = model->features().action_kind();
  request.progress = [&](int finished, int of) { report_(rollouts_text, at(0.5 + 0.5 * finished / of), false); };
  std::vector<Episode> episodes;
  keep_rollouts(request, s_.previews, r.results, episodes);
  r.stats = evaluate([&] { return std::make_unique<ModelPolicy>(model); }, s_.world, request, inner);
  pick_previews(episodes, seed, r.success_preview, r.failure_preview);
  return r;
}

LeaderboardRow RowRunner::baseline_row(const std::string& name, Cluster& inner, double from, double span) const {
  report_("baseline " + name, from, true);
  const auto t0 = std::chrono::steady_clock::now();
  const PolicyFactory policy = baseline(name).make(s_.world, *s_.profile, s_.seed, s_.threads);
  LeaderboardRow row{name, "baseline"};
  row.fit_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  row.train_error = row.test_error = -1;
  for (int k = 0; k < s_.seeds; ++k) {
    EvalRequest request;
    request.episodes = s_.episodes;
    request.seed = s_.seed + static_cast<std::uint64_t>(k);
    request.threads = s_.threads;
    request.perturbation = s_.perturbation;
    request.estimator = estimator_config(s_.estimator.empty() ? "none" : s_.estimator);
    request.progress = [&](int finished, int of) {
      report_("baseline " + name, from + span * (k + static_cast<double>(finished) / of) / s_.seeds, false);
    };
    std::vector<EpisodeResult> results;
    std::vector<Episode> episodes;
    keep_rollouts(request, s_.previews, results, episodes);
    const EvalStats st = evaluate(policy, s_.world, request, inner);
    add_outcomes(row, st, s_.seeds);
    std::vector<RowPreview> success, failure;
    pick_previews(episodes, request.seed, success, failure);
    add_rollouts(row, request.seed, results, success, failure);
  }
  return row;
}

LeaderboardRow RowRunner::combine(const std::string& learner, const std::string& features, const std::string& regressor,
                                  const std::vector<SeedResult>& seeds) const {
  LeaderboardRow row{regressor, learner, features};
  for (std::size_t k = 0; k < seeds.size(); ++k) {
    const SeedResult& r = seeds[k];
    add_rollouts(row, s_.seed + k, r.results, r.success_preview, r.failure_preview);
    row.fit_s += r.fit_s / s_.seeds;
    if (r.train_error < 0)
      row.train_error = -1;  // no error (a map of the arm's links or torques): printed "-"
    else
      row.train_error += r.train_error / s_.seeds;
    if (!r.has_test)
      row.test_error = -1;  // no test episode: printed "-"
    else
      row.test_error += r.test_error / s_.seeds;
    add_outcomes(row, r.stats, s_.seeds);
  }
  return row;
}

double estimated_row_cost(const std::string& learner, const std::string& regressor, const std::string& features,
                          const Profile& profile, int rollouts) {
  // Seconds on one core, from the measured quick and paper leaderboards (docs/learners.md,
  // docs/notebook/2026-11-27-learners-page-history.md "The paper profile", docs/scaling.md).
  // Only the ratios matter: they decide which rank gets which row. A profile
  // other than "paper" is costed as quick.
  const bool paper = profile.name == "paper";
  if (learner == "baseline") {
    const BaselineInfo& b = baseline(regressor);
    const double budget = static_cast<double>(b.budget(profile)) / b.budget(leaderboard_profile("quick"));
    return budget * b.quick_seconds + rollouts * 0.01;
  }
  auto pick = [](const std::map<std::string, double>& table, const std::string& key, double otherwise) {
    const auto it = table.find(key);
    return it == table.end() ? otherwise : it->second;
  };
  // One fit on the demonstrations (80 episodes, ~20,000 rows), and the time per policy step.
  const double fit = pick({{"gbt", 10.0}, {"rbf_svr", 10.0}, {"mlp", 1.0}, {"random_forest", 0.2}, {"knn", 0.01}, {"linear_svr", 0.02}}, regressor, 2.0);
  double step_us = pick({{"knn", 60.0}, {"rbf_svr", 80.0}, {"gbt", 10.0}}, regressor, 2.0);
  if (features != "state" && features != "-") step_us *= regressor == "knn" ? 10.0 : 1.5;
  // What a learner adds: its data relative to the demonstrations (fits grow with it, a kernel
  // SVR's with its square), its fits, and its own simulation (expert rollouts, corrections).
  const double rows = pick({{"bc", 1.0}, {"dagger", paper ? 3.0 : 1.5}, {"dart", 3.0}, {"dad", 1.5}}, learner, 2.0);
  const double fits = pick({{"bc", 1.0}, {"dagger", paper ? 6.0 : 3.0}, {"dart", 1.0}, {"dad", paper ? 31.0 : 3.0}}, learner, 3.0);
  const double own = pick({{"bc", 0.0}, {"dagger", paper ? 80.0 : 4.0}, {"dart", 2.0}, {"dad", paper ? 400.0 : 20.0}}, learner, 10.0);
  const double fit_cost = fits * fit * (regressor == "rbf_svr" ? rows * rows : rows);
  const double rollout_steps = (rollouts + (learner == "dagger" || learner == "dad" ? fits * 16 : 0)) * 300.0;
  return fit_cost + own + rollout_steps * (step_us + 25.0) * 1e-6;
}

}  // namespace dicestack
