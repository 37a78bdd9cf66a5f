#include <dicestack/core/standardizer.hpp>

#include <cmath>

#include <dicestack/core/error.hpp>

namespace dicestack {

Standardizer Standardizer::fit(const Matrix& rows, std::vector<std::string>* warnings,
                               const std::vector<std::string>* column_names) {
  if (rows.rows() == 0) throw InputError("standardizer: no rows to fit on");
  if (!rows.allFinite()) throw InputError("standardizer: rows hold a NaN or infinite value");
  Standardizer s;
  const auto n = static_cast<double>(rows.rows());
  for (Eigen::Index j = 0; j < rows.cols(); ++j) {
    const bool constant = rows.col(j).minCoeff() == rows.col(j).maxCoeff();
    const double mean = constant ? rows(0, j) : rows.col(j).sum() / n;
    const double var = (rows.col(j).array() - mean).square().sum() / n;
    double sigma = std::sqrt(var);
    // n equal values rarely sum to exactly n times their value: the rounding of the mean leaves
    // a sigma of about 1e-16 |mean|, which would blow any other value up by 1e16.
    if (!(sigma > 0.0) || constant) {
      sigma = 1.0;
      if (warnings) {
        const std::string name = column_names && static_cast<std::size_t>(j) < column_names->size()
                                     ? (*column_names)[static_cast<std::size_t>(j)]
                                     : "column " + std::to_string(j);
        warnings->push_back("standardizer: " + name + " is constant (" + std::to_string(mean) + "); using sigma 1");
      }
    }
    s.mean.push_back(mean);
    s.sigma.push_back(sigma);
  }
  return s;
}

Matrix Standardizer::apply(const Matrix& rows) const {
  if (static_cast<std::size_t>(rows.cols()) != dims())
    throw InputError("standardizer: rows have " + std::to_string(rows.cols()) + " columns, fitted on " +
                     std::to_string(dims()));
  Matrix out(rows.rows(), rows.cols());
  for (Eigen::Index i = 0; i < rows.rows(); ++i)
    apply_row({rows.row(i).data(), dims()}, {out.row(i).data(), dims()});
  return out;
}

void Standardizer::apply_row(std::span<const double> in, std::span<double> out) const {
  for (std::size_t j = 0; j < mean.size(); ++j) out[j] = (in[j] - mean[j]) / sigma[j];
}

void Standardizer::invert_row(std::span<const double> in, std::span<double> out) const {
  for (std::size_t j = 0; j < mean.size(); ++j) out[j] = in[j] * sigma[j] + mean[j];
}

}  // namespace dicestack
