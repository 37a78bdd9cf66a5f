#pragma once
// The Regressor interface every built-in and plugin regressor implements. Public methods are
// non-virtual and check shapes, finiteness and the fitted state once, for everyone; a
// regressor implements the private do_* methods (STYLE 3).
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include <dicestack/core/matrix.hpp>
#include <dicestack/regressors/params.hpp>

namespace dicestack {

class Regressor {
 public:
  Regressor(std::string name, Params params) : name_(std::move(name)), params_(std::move(params)) {}
  virtual ~Regressor() = default;
  Regressor(const Regressor&) = delete;
  Regressor& operator=(const Regressor&) = delete;

  /// Registry name, e.g. "knn".
  const std::string& name() const { return name_; }
  const Params& params() const { return params_; }
  bool fitted() const { return input_dim_ > 0; }
  std::size_t input_dim() const { return input_dim_; }
  std::size_t output_dim() const { return output_dim_; }

  /// Fits on standardised rows x (N x d) and labels y (N x k); `seed` drives every random
  /// choice, so the same data and seed give the same model. Refitting replaces the model.
  /// Throws InputError naming the regressor for empty, mismatched or non-finite input.
  void fit(const Matrix& x, const Matrix& y, std::uint64_t seed);

  /// Predicts every row of x. Throws InputError if unfitted or x has the wrong width.
  Matrix predict(const Matrix& x) const;

  /// Hot path: one row into y. Thread-safe; the built-ins on our own code do not allocate.
  /// Throws InputError if unfitted or the spans have the wrong sizes.
  void predict_row(std::span<const double> x, std::span<double> y) const;

  /// The backend's model as text (OpenCV YAML, xgboost JSON, ...), for model files.
  std::string save_payload() const;
  /// Restores a model saved by save_payload with the given dimensions. Throws InputError
  /// naming the regressor if the payload is malformed.
  void load_payload(std::string_view payload, std::size_t input_dim, std::size_t output_dim);

 private:
  virtual void do_fit(const Matrix& x, const Matrix& y, std::uint64_t seed) = 0;
  virtual void do_predict_row(std::span<const double> x, std::span<double> y) const = 0;
  /// Batch prediction; the default calls do_predict_row per row.
  virtual void do_predict(const Matrix& x, Matrix& y) const;
  virtual std::string do_save() const = 0;
  virtual void do_load(std::string_view payload, std::size_t input_dim, std::size_t output_dim) = 0;

  std::string name_;
  Params params_;
  std::size_t input_dim_ = 0;
  std::size_t output_dim_ = 0;
};

}  // namespace dicestack
