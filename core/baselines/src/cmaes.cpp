#include <dicestack/core/cmaes.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

#include <Eigen/Eigenvalues>

#include <dicestack/core/error.hpp>

namespace dicestack {

Cmaes::Cmaes(const Eigen::VectorXd& x0, const CmaesOptions& options)
    : n_(static_cast<int>(x0.size())), options_(options), rng_(options.seed) {
  if (n_ < 1) throw InputError("cmaes: needs at least one dimension");
  if (!(options.sigma0 > 0.0)) throw InputError("cmaes: sigma0 must be positive");
  if (!x0.allFinite()) throw InputError("cmaes: start point holds NaN or infinity");
  const double n = n_;
  lambda_ = options.population > 0 ? options.population : 4 + static_cast<int>(std::floor(3.0 * std::log(n)));
  mu_ = lambda_ / 2;
  weights_.resize(mu_);
  for (int i = 0; i < mu_; ++i) weights_[i] = std::log(mu_ + 0.5) - std::log(i + 1.0);
  weights_ /= weights_.sum();
  mueff_ = 1.0 / weights_.squaredNorm();
  cc_ = (4.0 + mueff_ / n) / (n + 4.0 + 2.0 * mueff_ / n);
  cs_ = (mueff_ + 2.0) / (n + mueff_ + 5.0);
  c1_ = 2.0 / ((n + 1.3) * (n + 1.3) + mueff_);
  cmu_ = std::min(1.0 - c1_, 2.0 * (mueff_ - 2.0 + 1.0 / mueff_) / ((n + 2.0) * (n + 2.0) + mueff_));
  damps_ = 1.0 + 2.0 * std::max(0.0, std::sqrt((mueff_ - 1.0) / (n + 1.0)) - 1.0) + cs_;
  chi_n_ = std::sqrt(n) * (1.0 - 1.0 / (4.0 * n) + 1.0 / (21.0 * n * n));
  mean_ = x0;
  pc_ = ps_ = Eigen::VectorXd::Zero(n_);
  c_ = b_ = bd_ = Eigen::MatrixXd::Identity(n_, n_);
  d_ = Eigen::VectorXd::Ones(n_);
  sigma_ = options.sigma0;
  best_x_ = x0;
  best_f_ = HUGE_VAL;
}

const Eigen::MatrixXd& Cmaes::ask() {
  z_.resize(lambda_, n_);
  for (Eigen::Index i = 0; i < z_.size(); ++i) z_.data()[i] = rng_.normal();
  x_ = (z_ * bd_.transpose() * sigma_).rowwise() + mean_.transpose();
  asked_ = true;
  return x_;
}

void Cmaes::tell(const std::vector<double>& values) {
  if (!asked_) throw InputError("cmaes: tell() without ask()");
  if (values.size() != static_cast<std::size_t>(lambda_))
    throw InputError("cmaes: got " + std::to_string(values.size()) + " values for " + std::to_string(lambda_) + " candidates");
  for (double v : values)
    if (std::isnan(v)) throw InputError("cmaes: a candidate's value is NaN");
  asked_ = false;
  evaluations_ += lambda_;
  ++iterations_;
  std::vector<int> order(static_cast<std::size_t>(lambda_));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return values[static_cast<std::size_t>(a)] < values[static_cast<std::size_t>(b)]; });
  if (values[static_cast<std::size_t>(order[0])] < best_f_) {
    best_f_ = values[static_cast<std::size_t>(order[0])];
    best_x_ = x_.row(order[0]).transpose();
  }
  recent_best_.push_back(values[static_cast<std::size_t>(order[0])]);

  const Eigen::VectorXd old_mean = mean_;
  Eigen::VectorXd zmean = Eigen::VectorXd::Zero(n_);
  mean_.setZero();
  for (int i = 0; i < mu_; ++i) {
    mean_ += weights_[i] * x_.row(order[static_cast<std::size_t>(i)]).transpose();
    zmean += weights_[i] * z_.row(order[static_cast<std::size_t>(i)]).transpose();
  }
  // Cumulation: evolution paths for step size and covariance.
  ps_ = (1.0 - cs_) * ps_ + std::sqrt(cs_ * (2.0 - cs_) * mueff_) * (b_ * zmean);
  const double ps_norm = ps_.norm();
  const double expected = std::sqrt(1.0 - std::pow(1.0 - cs_, 2.0 * iterations_));
  const bool hsig = ps_norm / expected / chi_n_ < 1.4 + 2.0 / (n_ + 1.0);
  const Eigen::VectorXd step = (mean_ - old_mean) / sigma_;
  pc_ = (1.0 - cc_) * pc_ + (hsig ? std::sqrt(cc_ * (2.0 - cc_) * mueff_) : 0.0) * step;
  // Rank-one and rank-mu update of the covariance.
  Eigen::MatrixXd artmp(n_, mu_);
  for (int i = 0; i < mu_; ++i) artmp.col(i) = (x_.row(order[static_cast<std::size_t>(i)]).transpose() - old_mean) / sigma_;
  c_ = (1.0 - c1_ - cmu_) * c_ + c1_ * (pc_ * pc_.transpose() + (hsig ? 0.0 : cc_ * (2.0 - cc_)) * c_) +
       cmu_ * artmp * weights_.asDiagonal() * artmp.transpose();
  sigma_ *= std::exp((cs_ / damps_) * (ps_norm / chi_n_ - 1.0));
  // Refresh B and D every few generations (the O(n^3) part).
  if (iterations_ - eigen_generation_ > lambda_ / ((c1_ + cmu_) * n_ * 10.0)) decompose();
}

void Cmaes::decompose() {
  eigen_generation_ = iterations_;
  c_ = 0.5 * (c_ + c_.transpose());  // keep it symmetric against round-off
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> solver(c_);
  b_ = solver.eigenvectors();
  d_ = solver.eigenvalues().cwiseMax(1e-20).cwiseSqrt();
  bd_ = b_ * d_.asDiagonal();
}

bool Cmaes::done() const {
  if (options_.max_evaluations > 0 && evaluations_ + lambda_ > options_.max_evaluations) return true;
  if (options_.max_iterations > 0 && iterations_ >= options_.max_iterations) return true;
  if (options_.max_evaluations <= 0 && options_.max_iterations <= 0) return false;
  const std::size_t window = static_cast<std::size_t>(10 + 30 * n_ / lambda_);
  if (recent_best_.size() >= window) {
    const auto [lo, hi] = std::minmax_element(recent_best_.end() - static_cast<std::ptrdiff_t>(window), recent_best_.end());
    if (*hi - *lo < options_.tol_fun) return true;
  }
  return sigma_ * d_.maxCoeff() < 1e-14;
}

}  // namespace dicestack
