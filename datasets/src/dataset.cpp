#include <dicestack/datasets/dataset.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/perturbation.hpp>

namespace dicestack {
namespace {

// What a policy was shown at each step of an episode run with perturbed sensing or delays, as
// a rollout showed it: the episode's own PerturbedChannel, replayed from the draw it saved (its
// noises come from the saved seed, whatever was chosen). It is replayed only where the rows
// differ: under observation noise or delay, and for an "/ahead" map under an action delay.
// What was pending or unseen is rebuilt from the labels, which are what was chosen only where
// the recording's actor labelled its own steps: a step the learner took (DAgger's mixture)
// records the expert's label instead, so an "/ahead" map refuses such an episode.
std::optional<PerturbedChannel> replayed_channel(const Episode& e, const FeatureMap& features) {
  if (e.perturbation.empty()) return std::nullopt;
  const PerturbationDraw d = channel_draw_from_json(e.perturbation, "episode \"" + e.name + "\"");
  const bool sensing = d.observation_delay > 0 ||
                       std::any_of(d.observation_noise.begin(), d.observation_noise.end(), [](double v) { return v > 0; });
  const nlohmann::json record = nlohmann::json::parse(e.perturbation, nullptr, false);
  if (sensing && record.is_object() && record.contains("estimator"))
    throw InputError("episode \"" + e.name + "\" was recorded with its expert behind an estimator: its actions answered "
                     "the estimate, and a row shows what the sensors gave; record a training set without --estimator");
  const bool delayed = d.action_delay > 0 || d.observation_delay > 0;
  if (!sensing && !(features.ahead() && delayed)) return std::nullopt;
  if (features.ahead() && delayed && std::find(e.sources.begin(), e.sources.end(), StepSource::policy) != e.sources.end())
    throw InputError("episode \"" + e.name + "\" ran under a delay with steps a learner chose, whose choices are not "
                     "recorded (only the expert's labels): an \"/ahead\" map cannot rebuild what was pending or unseen");
  return PerturbedChannel(d, features.action_kind());
}

}  // namespace

void check_rows_of(const Episode& e, const FeatureMap& features) {
  if (features.reads_links() && e.links.size() != e.states.size())
    throw InputError("episode \"" + e.name + "\": feature map \"" + features.name() +
                     "\" reads the arm's links, and the episode has no readings of them (record --embodiment arm "
                     "--controller joint_torque records them and the torques)");
  for (std::size_t t = 0; t < e.actions.size(); ++t)
    if (e.actions[t].kind() != features.action_kind())
      throw InputError("episode \"" + e.name + "\" step " + std::to_string(t) + ": feature map \"" + features.name() +
                       "\" answers " + std::string(action_kind_name(features.action_kind())) + " actions, the step's is for the " +
                       std::string(action_kind_name(e.actions[t].kind())) + " controller" +
                       (features.action_kind() == ActionKind::joint_torque
                            ? " (record --embodiment arm --controller joint_torque records torques)"
                            : ""));
}

namespace {

Dataset stack(const std::vector<const Episode*>& episodes, const FeatureMap& features, const RowFilter& rows = {}) {
  std::size_t n = 0;
  for (const Episode* e : episodes)
    for (std::size_t t = 0; t < e->size(); ++t) n += !rows || rows(*e, t);
  const auto width = static_cast<Eigen::Index>(features.width());
  Dataset d;
  d.x.resize(static_cast<Eigen::Index>(n), width);
  const std::size_t outputs = features.outputs();
  d.y.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(outputs));
  Eigen::Index row = 0;
  for (const Episode* e : episodes) {
    check_episode(*e);
    check_rows_of(*e, features);
    d.episode_begin.push_back(static_cast<std::size_t>(row));
    d.episode_names.push_back(e->name);
    std::optional<PerturbedChannel> channel = replayed_channel(*e, features);
    std::vector<State> seen;
    std::vector<Action> pending, unseen;
    for (std::size_t t = 0; t < e->size(); ++t) {
      if (channel) {
        seen.push_back(channel->observe(e->states[t]));
        pending.assign(channel->pending().begin(), channel->pending().end());
        unseen.assign(channel->unseen().begin(), channel->unseen().end());
      }
      if (!rows || rows(*e, t)) {
        const History h{std::span<const State>(channel ? seen.data() : e->states.data(), t + 1),
                        std::span<const Action>(e->actions.data(), t), pending, unseen,
                        e->links.empty() ? std::span<const ArmLinks>{} : std::span<const ArmLinks>(e->links.data(), t + 1)};
        features.compute(h, {d.x.row(row).data(), static_cast<std::size_t>(width)});
        features.label(h, e->actions[t], {d.y.row(row).data(), outputs});
        ++row;
      }
      if (channel) channel->execute(e->actions[t]);
    }
  }
  return d;
}

Dataset take_rows(const Dataset& all, const std::vector<std::size_t>& rows) {
  Dataset d;
  d.x.resize(static_cast<Eigen::Index>(rows.size()), all.x.cols());
  d.y.resize(static_cast<Eigen::Index>(rows.size()), all.y.cols());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    d.x.row(static_cast<Eigen::Index>(i)) = all.x.row(static_cast<Eigen::Index>(rows[i]));
    d.y.row(static_cast<Eigen::Index>(i)) = all.y.row(static_cast<Eigen::Index>(rows[i]));
  }
  return d;  // rows from many episodes: no episode boundaries
}

}  // namespace

Dataset make_dataset(const std::vector<Episode>& episodes, const FeatureMap& features, const RowFilter& rows) {
  std::vector<const Episode*> all;
  for (const auto& e : episodes) all.push_back(&e);
  return stack(all, features, rows);
}

bool is_test_episode(std::size_t index) { return index % 5 == 4; }

namespace {

std::string episode_split_text(std::size_t test, std::size_t all) {
  return "episodes: i % 5 == 4 is test (" + std::to_string(test) + " of " + std::to_string(all) + " episodes)";
}

}  // namespace

Split split_by_episode(const std::vector<Episode>& episodes, const FeatureMap& features) {
  std::vector<const Episode*> train, test;
  for (std::size_t i = 0; i < episodes.size(); ++i) (is_test_episode(i) ? test : train).push_back(&episodes[i]);
  if (train.empty()) throw InputError("episode split: no training episode among " + std::to_string(episodes.size()));
  return {stack(train, features), stack(test, features), episode_split_text(test.size(), episodes.size())};
}

std::vector<std::size_t> numpy_legacy_permutation(std::size_t n, std::uint32_t seed) {
  // RandomState(seed) seeds MT19937 with init_genrand(seed), as std::mt19937(seed) does;
  // shuffle swaps i with a j drawn by masked rejection from 32-bit outputs, for i = n-1..1.
  std::mt19937 mt(seed);
  std::vector<std::size_t> perm(n);
  for (std::size_t i = 0; i < n; ++i) perm[i] = i;
  for (std::size_t i = n; i-- > 1;) {
    std::uint32_t mask = static_cast<std::uint32_t>(i);
    mask |= mask >> 1;
    mask |= mask >> 2;
    mask |= mask >> 4;
    mask |= mask >> 8;
    mask |= mask >> 16;
    std::uint32_t j;
    do j = static_cast<std::uint32_t>(mt()) & mask;
    while (j > i);
    std::swap(perm[i], perm[j]);
  }
  return perm;
}

Split split_by_rows(const std::vector<Episode>& episodes, double test_fraction, std::uint32_t seed,
                    const FeatureMap& features) {
  if (!(test_fraction > 0.0 && test_fraction < 1.0))
    throw ConfigError("row split: test fraction must be in (0, 1), got " + std::to_string(test_fraction));
  const Dataset all = make_dataset(episodes, features);
  const std::size_t n = all.rows();
  // scikit-learn: n_test = ceil(fraction * n), test = perm[:n_test], train = perm[n_test:].
  const auto n_test = static_cast<std::size_t>(std::ceil(test_fraction * static_cast<double>(n)));
  if (n_test == 0 || n_test >= n) throw InputError("row split: " + std::to_string(n) + " rows are too few to split");
  const auto perm = numpy_legacy_permutation(n, seed);
  const std::vector<std::size_t> test(perm.begin(), perm.begin() + static_cast<std::ptrdiff_t>(n_test));
  const std::vector<std::size_t> train(perm.begin() + static_cast<std::ptrdiff_t>(n_test), perm.end());
  char text[160];
  std::snprintf(text, sizeof text, "rows: random %.0f%% of %zu rows is test (numpy permutation, seed %u)",
                100.0 * test_fraction, n, seed);
  return {take_rows(all, train), take_rows(all, test), text};
}

DemoSplit::DemoSplit(const std::vector<Episode>& episodes, const std::string& rule) : all_(episodes), rule_(rule) {
  if (rule == "episodes") {
    for (std::size_t i = 0; i < episodes.size(); ++i) (is_test_episode(i) ? held_out_ : train_).push_back(episodes[i]);
    if (train_.empty()) throw InputError("episode split: no training episode among " + std::to_string(episodes.size()));
  } else if (rule == "rows") {
    const Split& rows = matrices();
    Episode pseudo;
    pseudo.name = "training-rows";
    for (Eigen::Index i = 0; i < rows.train.x.rows(); ++i) {
      State st;
      Action a;
      for (std::size_t j = 0; j < kStateDim; ++j) st[j] = rows.train.x(i, static_cast<Eigen::Index>(j));
      for (std::size_t j = 0; j < kActionDim; ++j) a[j] = rows.train.y(i, static_cast<Eigen::Index>(j));
      pseudo.states.push_back(st);
      pseudo.actions.push_back(a);
      pseudo.sources.push_back(StepSource::human);
    }
    train_.push_back(std::move(pseudo));
  } else if (rule == "none") {
    if (episodes.empty()) throw InputError("no demonstration to train on");
    train_ = episodes;
  } else {
    throw ConfigError("split \"" + rule + "\" is not one of episodes, rows, none");
  }
}

std::string DemoSplit::description() const {
  if (rule_ == "episodes") return episode_split_text(held_out_.size(), all_.size());
  if (rule_ == "none") return "none: all " + std::to_string(all_.size()) + " episodes are training";
  return matrices().description;
}

const Split& DemoSplit::matrices(const FeatureMap& features) const {
  auto& slot = matrices_[features.name()];
  if (!slot) {
    if (rule_ == "rows" && features.name() != state_features().name())
      throw ConfigError("features \"" + features.name() +
                        "\": the row split shuffles the rows into one pseudo-episode of states and actions, which only "
                        "the \"state\" map reads as recorded: use the episode split");
    if (rule_ == "episodes") {
      slot = std::make_unique<Split>(split_by_episode(all_, features));
    } else if (rule_ == "rows") {
      slot = std::make_unique<Split>(split_by_rows(all_, 0.25, 42, features));
    } else {
      slot = std::make_unique<Split>(Split{make_dataset(all_, features), make_dataset({}, features), description()});
    }
  }
  return *slot;
}

}  // namespace dicestack
