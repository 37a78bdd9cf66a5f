#include <dicestack/datasets/metrics.hpp>

#include <cmath>

#include <dicestack/core/error.hpp>

namespace dicestack {

std::vector<double> column_sigma(const Matrix& labels) {
  std::vector<double> sigma;
  const auto n = static_cast<double>(labels.rows());
  for (Eigen::Index j = 0; j < labels.cols(); ++j) {
    const double mean = labels.col(j).sum() / n;
    const double sd = std::sqrt((labels.col(j).array() - mean).square().sum() / n);
    sigma.push_back(sd > 0.0 ? sd : 1.0);
  }
  return sigma;
}

double scaled_l1_error(const Matrix& y, const Matrix& y_hat, std::span<const double> sigma) {
  if (y.rows() != y_hat.rows() || y.cols() != y_hat.cols())
    throw InputError("scaled L1 error: labels are " + std::to_string(y.rows()) + " x " + std::to_string(y.cols()) +
                     ", predictions " + std::to_string(y_hat.rows()) + " x " + std::to_string(y_hat.cols()));
  if (sigma.size() != static_cast<std::size_t>(y.cols()))
    throw InputError("scaled L1 error: " + std::to_string(sigma.size()) + " sigmas for " + std::to_string(y.cols()) +
                     " columns");
  for (std::size_t j = 0; j < sigma.size(); ++j)
    if (!(sigma[j] > 0.0))
      throw InputError("scaled L1 error: sigma of column " + std::to_string(j) + " is " + std::to_string(sigma[j]) +
                       "; it must be positive");
  if (y.rows() == 0) return 0.0;
  double total = 0.0;
  for (Eigen::Index i = 0; i < y.rows(); ++i)
    for (Eigen::Index j = 0; j < y.cols(); ++j)
      total += std::abs(y(i, j) - y_hat(i, j)) / sigma[static_cast<std::size_t>(j)];
  return total / static_cast<double>(y.rows());
}

}  // namespace dicestack
