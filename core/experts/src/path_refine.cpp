#include "path_refine.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <dicestack/core/cmaes.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>

#include "path_trial.hpp"

namespace dicestack::tracker_detail {

namespace si = state_index;

namespace {

constexpr std::uint64_t kRefineStartStream = 0x726566696e53ULL;  // "refinS"
constexpr std::uint64_t kRefineNoiseStream = 0x726566696e4eULL;  // "refinN"
constexpr std::uint64_t kRefineSearchStream = 0x726566696e43ULL; // "refinC"
constexpr std::uint64_t kValidationStream = 0x726566696e56ULL;   // "refinV"

// `base` (folded) moved by x: per axis, refine_knots Gaussian bumps evenly spaced over the
// path, each of height clip(x) x refine_range. Axes x, y and angle move the cup's pose, and the
// velocities get the offsets' rates, so the follower's feed-forward and its pose target agree;
// the timing axis (when its range is above 0) plays step t of the path at time t + its offset,
// never earlier than the step before, the velocities scaled by the local speed.
CupPath offset_path(const CupPath& base, const Eigen::VectorXd& x, const TrackerConfig& c, double dt) {
  constexpr std::size_t pose[3] = {si::kCupX, si::kCupY, si::kCupAngle};
  constexpr std::size_t velocity[3] = {si::kCupVx, si::kCupVy, si::kCupW};
  const auto knots = static_cast<std::size_t>(c.refine_knots);
  const std::size_t n = base.states.size();
  const double last = static_cast<double>(n - 1);
  const double spacing = knots > 1 ? last / static_cast<double>(knots - 1) : last;
  const double width = std::max(spacing, 1.0);
  auto bump = [&](std::size_t j, double t, double& rate) {  // rate per step
    const double centre = knots > 1 ? static_cast<double>(j) * spacing : 0.5 * last;
    const double u = (t - centre) / width;
    const double value = std::exp(-0.5 * u * u);
    rate = -u / width * value;
    return value;
  };
  auto height = [&](std::size_t axis, std::size_t j) {
    return std::clamp(x[static_cast<Eigen::Index>(axis * knots + j)], -1.0, 1.0) * c.refine_range[axis];
  };
  const bool timed = c.refine_range[3] > 0.0;
  CupPath out = base;
  double played = 0.0;  // the latest point of the path played so far: time never runs backwards
  for (std::size_t t = 0; t < n; ++t) {
    double u = static_cast<double>(t), speed = 1.0;
    if (timed) {
      double shift = 0.0, shift_rate = 0.0;
      for (std::size_t j = 0; j < knots; ++j) {
        double rate = 0.0;
        const double b = bump(j, static_cast<double>(t), rate);
        shift += height(3, j) / dt * b;
        shift_rate += height(3, j) / dt * rate;
      }
      u = std::max(played, std::clamp(u + shift, 0.0, last));
      speed = std::max(0.2, 1.0 + shift_rate);
      played = u;
    }
    const auto i = static_cast<std::size_t>(u);
    const std::size_t next = std::min(i + 1, n - 1);
    const double f = u - static_cast<double>(i);
    for (std::size_t k = 0; k < 3; ++k) {
      const double a = base.states[i][pose[k]], b = base.states[next][pose[k]];
      const double va = base.states[i][velocity[k]], vb = base.states[next][velocity[k]];
      out.states[t][pose[k]] = a + f * (k == 2 ? std::remainder(b - a, 2.0 * std::numbers::pi) : b - a);
      out.states[t][velocity[k]] = speed * (va + f * (vb - va));
    }
    for (std::size_t j = 0; j < knots; ++j) {
      double rate = 0.0;
      const double b = bump(j, static_cast<double>(t), rate);
      for (std::size_t k = 0; k < 3; ++k) {
        out.states[t][pose[k]] += height(k, j) * b;
        out.states[t][velocity[k]] += height(k, j) * rate / dt;
      }
    }
  }
  return out;
}

// For each path and each start of [first, first + count), path-major: 1 per success, followed
// clean and under refine_noise, plus under 0.2 for each failure that ends near a stack without a
// wall (so floor() of a value is its successes). Every (path, start) is an item of its own.
std::vector<double> start_values(const std::vector<CupPath>& paths, const WorldConfig& world, const TrackerConfig& c,
                                std::uint64_t seed, std::size_t first, std::size_t count, int threads, Cluster& cluster) {
  EnvPool envs(world, threads), sims(world, threads);
  const auto values = distributed_map<double>(
      cluster, paths.size() * count, threads,
      [&](std::size_t item, int w) {
        const std::size_t p = item / count, start_index = first + item % count;
        const State start = random_start_state(world, training_start_seed(derive_seed(seed, kRefineStartStream), start_index));
        DiceEnv& env = envs.at(w);
        env.reset_to(start, 0);
        const EnvSnapshot snap = env.snapshot();
        const PathFollower follower(paths[p], {}, start, 0, c.gain, c.keep_extremes);
        double value = 0.0;
        for (const bool noisy : {false, true}) {
          const Trial trial = simulate(follower, sims.at(w), snap, c.hold_steps, c.controller, noisy ? c.refine_noise : Action{},
                                       derive_seed(derive_seed(seed, kRefineNoiseStream), start_index));
          if (trial.success) value += 1.0;
          else if (trial.score > -1000.0) value += 0.2 / (1.0 - trial.score);
        }
        return value;
      },
      [](const double& v) { return Packer().put(v).take(); },
      [](std::string_view b) { return Unpacker(b, "refinement value").get<double>(); });
  return values;
}

}  // namespace

CupPath refine_path(const CupPath& path, const WorldConfig& world, const TrackerConfig& c, std::uint64_t seed, int threads,
                    Cluster& cluster, const std::function<void(int, int)>& generation_done) {
  const CupPath base = folded(path);
  const double dt = world.physics.control_dt;
  const auto probes = static_cast<std::size_t>(c.refine_probes);
  CmaesOptions o;
  o.sigma0 = 0.3;  // in units of refine_range
  o.max_iterations = c.refine;
  o.seed = derive_seed(seed, kRefineSearchStream);
  const int axes = c.refine_range[3] > 0.0 ? 4 : 3;
  Cmaes es(Eigen::VectorXd::Zero(axes * c.refine_knots), o);
  std::size_t generation = 0;
  while (!es.done()) {
    // Fresh starts each generation, the same for every candidate of it (common random numbers).
    const Eigen::MatrixXd& x = es.ask();
    std::vector<CupPath> candidates;
    for (Eigen::Index r = 0; r < x.rows(); ++r) candidates.push_back(offset_path(base, x.row(r).transpose(), c, dt));
    const auto values = start_values(candidates, world, c, seed, generation * probes, probes, threads, cluster);
    std::vector<double> loss(candidates.size(), 0.0);
    for (std::size_t item = 0; item < values.size(); ++item) loss[item / probes] -= values[item];
    es.tell(loss);
    ++generation;
    if (generation_done) generation_done(static_cast<int>(generation), c.refine);
  }
  CupPath out = offset_path(base, es.mean(), c, dt);
  out.name = path.name + " (refined)";
  return out;
}

std::vector<int> validation_successes(const std::vector<CupPath>& paths, const WorldConfig& world, const TrackerConfig& c,
                                      std::uint64_t seed, int threads, Cluster& cluster) {
  std::vector<CupPath> played;
  for (const auto& p : paths) played.push_back(folded(p));
  const std::size_t count = 4 * static_cast<std::size_t>(c.refine_probes);
  const auto values = start_values(played, world, c, derive_seed(seed, kValidationStream), 0, count, threads, cluster);
  std::vector<int> out(paths.size(), 0);
  for (std::size_t item = 0; item < values.size(); ++item) out[item / count] += static_cast<int>(std::floor(values[item]));
  return out;
}

}  // namespace dicestack::tracker_detail
