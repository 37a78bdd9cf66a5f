#pragma once
// CMA-ES with pycma's defaults, ask/tell with batch evaluation (DESIGN: pagmo 2.18's cmaes
// samples with an O(n^3) product per sample and cannot evaluate a batch in parallel).
// Positive recombination weights only (no active update); the eigendecomposition is refreshed
// lazily, so a generation costs O(lambda n^2).
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include <dicestack/core/rng.hpp>

namespace dicestack {

struct CmaesOptions {
  int population = 0;        ///< lambda; 0 means pycma's 4 + floor(3 ln n)
  double sigma0 = 0.25;      ///< initial step size, absolute (in the search space's units)
  int max_evaluations = 0;   ///< budget; 0 means unlimited (use max_iterations)
  int max_iterations = 0;    ///< generations; 0 means unlimited (use max_evaluations)
  double tol_fun = 1e-12;    ///< stop when the best values of recent generations span less
  std::uint64_t seed = 0;
};

/// Minimises by ask() -> evaluate every row -> tell(values), until done().
class Cmaes {
 public:
  Cmaes(const Eigen::VectorXd& x0, const CmaesOptions& options);

  /// The next generation: lambda x n, one candidate per row.
  const Eigen::MatrixXd& ask();
  /// Values of the rows of the last ask(), lower is better. Throws InputError on a size
  /// mismatch or NaN.
  void tell(const std::vector<double>& values);

  bool done() const;
  int population() const { return lambda_; }
  int evaluations() const { return evaluations_; }
  int iterations() const { return iterations_; }
  double sigma() const { return sigma_; }
  const Eigen::VectorXd& mean() const { return mean_; }
  /// The best point evaluated so far and its value.
  const Eigen::VectorXd& best() const { return best_x_; }
  double best_value() const { return best_f_; }

 private:
  void decompose();

  int n_, lambda_, mu_;
  CmaesOptions options_;
  Eigen::VectorXd weights_;
  double mueff_, cc_, cs_, c1_, cmu_, damps_, chi_n_;
  Eigen::VectorXd mean_, pc_, ps_;
  Eigen::MatrixXd c_, b_, bd_;  // covariance, eigenvectors, B * diag(sqrt(eigenvalues))
  Eigen::VectorXd d_;
  double sigma_;
  Eigen::MatrixXd z_, x_;  // last generation: standard normal draws and candidates
  Rng rng_;
  int evaluations_ = 0, iterations_ = 0, eigen_generation_ = 0;
  bool asked_ = false;
  Eigen::VectorXd best_x_;
  double best_f_;
  std::vector<double> recent_best_;
};

}  // namespace dicestack
