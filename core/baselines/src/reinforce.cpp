#include <dicestack/core/reinforce.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>

#include <dicestack/core/cost.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {

namespace {

Eigen::MatrixXd glorot(Eigen::Index rows, Eigen::Index cols, Rng& rng) {
  const double limit = std::sqrt(6.0 / static_cast<double>(rows + cols));
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = rng.uniform(-limit, limit);
  return m;
}

}  // namespace

PolicyNetwork::PolicyNetwork(int hidden, double leak, std::uint64_t seed) : leak_(leak) {
  Rng rng(seed);
  w1_ = glorot(hidden, kStateDim, rng);
  w2_ = glorot(hidden, hidden, rng);
  w3_ = glorot(kActionDim, hidden, rng) * 0.1;  // start near the zero action
  b1_ = Eigen::VectorXd::Zero(hidden);
  b2_ = Eigen::VectorXd::Zero(hidden);
  b3_ = Eigen::VectorXd::Zero(kActionDim);
}

Eigen::Index PolicyNetwork::size() const {
  return w1_.size() + b1_.size() + w2_.size() + b2_.size() + w3_.size() + b3_.size();
}

Eigen::VectorXd PolicyNetwork::params() const {
  Eigen::VectorXd p(size());
  Eigen::Index at = 0;
  blocks(*this, [&](const auto& b) {
    p.segment(at, b.size()) = Eigen::Map<const Eigen::VectorXd>(b.data(), b.size());
    at += b.size();
  });
  return p;
}

void PolicyNetwork::set_params(const Eigen::VectorXd& p) {
  if (p.size() != size()) throw InputError("policy network: " + std::to_string(p.size()) + " parameters, expected " + std::to_string(size()));
  Eigen::Index at = 0;
  blocks(*this, [&](auto& b) {
    Eigen::Map<Eigen::VectorXd>(b.data(), b.size()) = p.segment(at, b.size());
    at += b.size();
  });
}

Eigen::Vector3d PolicyNetwork::mean(const Eigen::VectorXd& x) const {
  const auto leaky = [this](double v) { return v > 0.0 ? v : leak_ * v; };
  const Eigen::VectorXd h1 = (w1_ * x + b1_).unaryExpr(leaky);
  const Eigen::VectorXd h2 = (w2_ * h1 + b2_).unaryExpr(leaky);
  return (w3_ * h2 + b3_).array().tanh();
}

void PolicyNetwork::accumulate_gradient(const Eigen::VectorXd& x, const Eigen::Vector3d& a, double sigma, double weight,
                                        Eigen::VectorXd& grad) const {
  const auto leaky = [this](double v) { return v > 0.0 ? v : leak_ * v; };
  const auto slope = [this](double v) { return v > 0.0 ? 1.0 : leak_; };
  const Eigen::VectorXd z1 = w1_ * x + b1_, h1 = z1.unaryExpr(leaky);
  const Eigen::VectorXd z2 = w2_ * h1 + b2_, h2 = z2.unaryExpr(leaky);
  const Eigen::Vector3d mu = (w3_ * h2 + b3_).array().tanh();
  // d log N(a; mu, sigma^2 I) / d mu = (a - mu) / sigma^2, then back through tanh and the layers.
  const Eigen::Vector3d dz3 = weight * ((a - mu) / (sigma * sigma)).cwiseProduct((1.0 - mu.array().square()).matrix());
  const Eigen::VectorXd dz2 = (w3_.transpose() * dz3).cwiseProduct(z2.unaryExpr(slope));
  const Eigen::VectorXd dz1 = (w2_.transpose() * dz2).cwiseProduct(z1.unaryExpr(slope));
  Eigen::Index at = 0;
  auto add = [&](const auto& block) {
    const Eigen::Index n = block.size();
    for (Eigen::Index c = 0; c < block.cols(); ++c)
      for (Eigen::Index r = 0; r < block.rows(); ++r) grad[at + c * block.rows() + r] += block(r, c);
    at += n;
  };
  add(Eigen::MatrixXd(dz1 * x.transpose()));
  add(dz1);
  add(Eigen::MatrixXd(dz2 * h1.transpose()));
  add(dz2);
  add(Eigen::MatrixXd(dz3 * h2.transpose()));
  add(dz3);
}

namespace {

struct EpisodeTrace {
  std::vector<Eigen::VectorXd> inputs;
  std::vector<Eigen::Vector3d> actions;  // sampled, in scaled units (before clipping)
  std::vector<double> rewards;
  std::vector<State> states;  // after each step
};

// An episode as bytes for the ranks (every double kept bit for bit).
std::string pack_trace(const EpisodeTrace& e) {
  Packer p;
  p.put<std::uint64_t>(e.rewards.size());
  for (std::size_t t = 0; t < e.rewards.size(); ++t) {
    p.put<std::uint64_t>(static_cast<std::uint64_t>(e.inputs[t].size()));
    for (Eigen::Index j = 0; j < e.inputs[t].size(); ++j) p.put(e.inputs[t][j]);
    for (Eigen::Index j = 0; j < 3; ++j) p.put(e.actions[t][j]);
    p.put(e.rewards[t]).put(e.states[t]);
  }
  return p.take();
}

EpisodeTrace unpack_trace(std::string_view bytes) {
  Unpacker u(bytes, "REINFORCE episode");
  EpisodeTrace e;
  const auto steps = static_cast<std::size_t>(u.get<std::uint64_t>());
  for (std::size_t t = 0; t < steps; ++t) {
    Eigen::VectorXd x(static_cast<Eigen::Index>(u.get<std::uint64_t>()));
    for (Eigen::Index j = 0; j < x.size(); ++j) x[j] = u.get<double>();
    Eigen::Vector3d a;
    for (Eigen::Index j = 0; j < 3; ++j) a[j] = u.get<double>();
    e.inputs.push_back(std::move(x));
    e.actions.push_back(a);
    e.rewards.push_back(u.get<double>());
    e.states.push_back(u.get<State>());
  }
  return e;
}

Eigen::VectorXd scaled_input(const State& s, const CostConfig& cost) {
  Eigen::VectorXd x(kStateDim);
  for (std::size_t j = 0; j < kStateDim; ++j) x[static_cast<Eigen::Index>(j)] = s[j] / cost.sigma[j];
  return x;
}

Action to_action(const Eigen::Vector3d& a, const WorldConfig& w) {
  Action out;
  for (std::size_t k = 0; k < kActionDim; ++k) out[k] = std::clamp(a[static_cast<Eigen::Index>(k)], -1.0, 1.0) * w.action.scale[k];
  return out;
}

// One episode of `steps`; with rng, actions are sampled around the mean, else the mean itself.
EpisodeTrace run_episode(DiceEnv& env, const PolicyNetwork& net, const State& start, const State& goal, int steps,
                         double sigma, Rng* rng) {
  EpisodeTrace e;
  State s = env.reset_to(start, 0);
  const WorldConfig& w = env.config();
  for (int t = 0; t < steps; ++t) {
    const Eigen::VectorXd x = scaled_input(s, w.cost);
    Eigen::Vector3d a = net.mean(x);
    if (rng)
      for (Eigen::Index k = 0; k < 3; ++k) a[k] += sigma * rng->normal();
    s = env.step(to_action(a, w)).observation;
    e.inputs.push_back(x);
    e.actions.push_back(a);
    e.rewards.push_back(-state_distance(s, goal, w.cost));
    e.states.push_back(s);
  }
  return e;
}

}  // namespace

Action PolicyNetwork::act(const State& state, const WorldConfig& world) const {
  return to_action(mean(scaled_input(state, world.cost)), world);
}

ReinforceResult reinforce(const WorldConfig& config, const ReinforceOptions& o,
                          const std::function<void(const ReinforcePoint&)>& progress) {
  if (o.iterations < 1 || o.batch < 1 || o.steps < 1 || o.hidden < 1)
    throw ConfigError("reinforce: iterations, batch, steps and hidden must be at least 1");
  if (!(o.sigma > 0.0) || !(o.learning_rate > 0.0)) throw ConfigError("reinforce: sigma and the learning rate must be positive");
  WorldConfig world = config;
  validate(world);
  world.episode.max_steps = std::max(world.episode.max_steps, o.steps);
  const State start = paper_start_state(world), goal = goal_state(world);
  const auto t0 = std::chrono::steady_clock::now();
  ReinforceResult result{PolicyNetwork(o.hidden, o.leak, derive_seed(o.seed, 0)), {}, {}, 0.0};
  PolicyNetwork& net = result.policy;
  Eigen::VectorXd theta = net.params(), m = Eigen::VectorXd::Zero(theta.size()), v = m;
  Eigen::VectorXd baseline = Eigen::VectorXd::Zero(o.steps);
  bool baseline_set = false;
  EnvPool envs(world, o.threads);
  auto env_of = [&](int w) -> DiceEnv& { return envs.at(w); };
  for (int it = 1; it <= o.iterations; ++it) {
    const std::vector<EpisodeTrace> traces = distributed_map<EpisodeTrace>(
        *o.cluster, static_cast<std::size_t>(o.batch), o.threads,
        [&](std::size_t k, int w) {
          Rng rng(derive_seed(derive_seed(o.seed, static_cast<std::uint64_t>(it)), k));
          return run_episode(env_of(w), net, start, goal, o.steps, o.sigma, &rng);
        },
        pack_trace, unpack_trace);
    // Returns G_t = sum_{u >= t} discount^(u - t) r_u, per episode.
    std::vector<Eigen::VectorXd> returns;
    double mean_return = 0.0;
    for (const auto& e : traces) {
      Eigen::VectorXd g(o.steps);
      double running = 0.0;
      for (int t = o.steps - 1; t >= 0; --t) g[t] = running = e.rewards[static_cast<std::size_t>(t)] + o.discount * running;
      returns.push_back(g);
      for (double r : e.rewards) mean_return += r / o.batch;
    }
    if (!baseline_set) {
      baseline.setZero();
      for (const auto& g : returns) baseline += g / o.batch;
      baseline_set = true;
    }
    std::vector<Eigen::VectorXd> grads(traces.size());
    parallel_for(traces.size(), o.threads, [&](std::size_t k, int) {
      grads[k] = Eigen::VectorXd::Zero(theta.size());
      for (int t = 0; t < o.steps; ++t) {
        const auto ut = static_cast<std::size_t>(t);
        net.accumulate_gradient(traces[k].inputs[ut], traces[k].actions[ut], o.sigma, returns[k][t] - baseline[t], grads[k]);
      }
    });
    Eigen::VectorXd grad = Eigen::VectorXd::Zero(theta.size());
    for (const auto& g : grads) grad += g / o.batch;
    for (const auto& g : returns) baseline = o.baseline_decay * baseline + (1.0 - o.baseline_decay) * g;
    // Adam, ascending the expected return.
    const double b1 = 0.9, b2 = 0.999, eps = 1e-8;
    m = b1 * m + (1.0 - b1) * grad;
    v = b2 * v + (1.0 - b2) * grad.cwiseAbs2();
    const double c1 = 1.0 - std::pow(b1, it), c2 = 1.0 - std::pow(b2, it);
    theta += o.learning_rate * ((m / c1).array() / ((v / c2).array().sqrt() + eps)).matrix();
    net.set_params(theta);

    const EpisodeTrace greedy = run_episode(env_of(0), net, start, goal, o.steps, o.sigma, nullptr);
    const ReinforcePoint point{it, mean_return, discounted_cost(greedy.states, goal, world.cost)};
    result.curve.push_back(point);
    if (progress) progress(point);
  }
  const EpisodeTrace greedy = run_episode(env_of(0), net, start, goal, o.steps, o.sigma, nullptr);
  for (const auto& a : greedy.actions) result.greedy_actions.push_back(to_action(a, world));
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

}  // namespace dicestack
