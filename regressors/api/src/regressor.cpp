#include <dicestack/regressors/regressor.hpp>

#include <dicestack/core/error.hpp>

namespace dicestack {

void Regressor::fit(const Matrix& x, const Matrix& y, std::uint64_t seed) {
  if (x.rows() == 0 || x.cols() == 0) throw InputError(name_ + ": cannot fit on an empty matrix");
  if (y.rows() != x.rows())
    throw InputError(name_ + ": " + std::to_string(x.rows()) + " input rows but " + std::to_string(y.rows()) + " labels");
  if (y.cols() == 0) throw InputError(name_ + ": labels have no columns");
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    if (!x.row(i).allFinite())
      throw InputError(name_ + ": input row " + std::to_string(i) + " holds NaN or infinity; inputs must be finite");
    if (!y.row(i).allFinite())
      throw InputError(name_ + ": label row " + std::to_string(i) + " holds NaN or infinity; labels must be finite");
  }
  input_dim_ = 0;  // unfitted until do_fit succeeds
  do_fit(x, y, seed);
  input_dim_ = static_cast<std::size_t>(x.cols());
  output_dim_ = static_cast<std::size_t>(y.cols());
}

Matrix Regressor::predict(const Matrix& x) const {
  if (!fitted()) throw InputError(name_ + ": predict called before fit");
  if (static_cast<std::size_t>(x.cols()) != input_dim_)
    throw InputError(name_ + ": inputs have " + std::to_string(x.cols()) + " columns, the model was fitted on " +
                     std::to_string(input_dim_));
  if (!x.allFinite()) throw InputError(name_ + ": inputs hold NaN or infinity");
  Matrix y(x.rows(), static_cast<Eigen::Index>(output_dim_));
  if (x.rows() > 0) do_predict(x, y);
  return y;
}

void Regressor::predict_row(std::span<const double> x, std::span<double> y) const {
  if (!fitted()) throw InputError(name_ + ": predict called before fit");
  if (x.size() != input_dim_ || y.size() != output_dim_)
    throw InputError(name_ + ": predict_row got " + std::to_string(x.size()) + " inputs and room for " +
                     std::to_string(y.size()) + " outputs; the model takes " + std::to_string(input_dim_) +
                     " and gives " + std::to_string(output_dim_));
  do_predict_row(x, y);
}

void Regressor::do_predict(const Matrix& x, Matrix& y) const {
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    do_predict_row({x.row(i).data(), input_dim_}, {y.row(i).data(), output_dim_});
}

std::string Regressor::save_payload() const {
  if (!fitted()) throw InputError(name_ + ": cannot save a model that was never fitted");
  return do_save();
}

void Regressor::load_payload(std::string_view payload, std::size_t input_dim, std::size_t output_dim) {
  if (input_dim == 0 || output_dim == 0) throw InputError(name_ + ": a model needs non-zero dimensions");
  input_dim_ = 0;
  do_load(payload, input_dim, output_dim);
  input_dim_ = input_dim;
  output_dim_ = output_dim;
}

}  // namespace dicestack
