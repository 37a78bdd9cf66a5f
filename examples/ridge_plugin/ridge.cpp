// An example dicestack regressor plugin: ridge regression, solved in closed form with Eigen.
// One class and one registration line; build it with the CMakeLists.txt beside this file
// against an installed dicestack (docs/plugins.md walks through it).
#include <cstring>

#include <Eigen/Cholesky>

#include <dicestack/core/error.hpp>
#include <dicestack/regressors/registry.hpp>

class Ridge final : public dicestack::Regressor {
 public:
  using Regressor::Regressor;  // (name, params): the registry constructs it

  // Parameters with their defaults, bounds and help; `--set lambda=0.5` is checked against it.
  static std::vector<dicestack::ParamSpec> schema() {
    return {{"lambda", dicestack::ParamType::real, "1", 0, 1e12, "L2 penalty on the weights", {}}};
  }

 private:
  // x and y arrive standardised, checked for shape and finiteness by the base class.
  void do_fit(const dicestack::Matrix& x, const dicestack::Matrix& y, std::uint64_t /*seed*/) override {
    Eigen::MatrixXd a(x.rows(), x.cols() + 1);
    a << x, Eigen::VectorXd::Ones(x.rows());  // last column: intercept
    Eigen::MatrixXd gram = a.transpose() * a;
    gram.diagonal().head(x.cols()).array() += params().real("lambda");
    w_ = gram.ldlt().solve(a.transpose() * y);  // (d + 1) x k
  }

  // The hot path: one row, no allocation.
  void do_predict_row(std::span<const double> x, std::span<double> y) const override {
    const auto d = static_cast<Eigen::Index>(x.size());
    for (std::size_t j = 0; j < y.size(); ++j) {
      const auto col = static_cast<Eigen::Index>(j);
      y[j] = Eigen::Map<const Eigen::VectorXd>(x.data(), d).dot(w_.col(col).head(d)) + w_(d, col);
    }
  }

  // The model file's payload: here, the weights as raw doubles after their shape.
  std::string do_save() const override {
    std::string out(2 * sizeof(Eigen::Index), '\0');
    const Eigen::Index shape[2] = {w_.rows(), w_.cols()};
    std::memcpy(out.data(), shape, sizeof shape);
    out.append(reinterpret_cast<const char*>(w_.data()), sizeof(double) * static_cast<std::size_t>(w_.size()));
    return out;
  }

  void do_load(std::string_view payload, std::size_t input_dim, std::size_t output_dim) override {
    Eigen::Index shape[2];
    if (payload.size() < sizeof shape) throw dicestack::InputError("ridge: payload too short");
    std::memcpy(shape, payload.data(), sizeof shape);
    if (shape[0] != static_cast<Eigen::Index>(input_dim + 1) || shape[1] != static_cast<Eigen::Index>(output_dim) ||
        payload.size() != sizeof shape + sizeof(double) * static_cast<std::size_t>(shape[0] * shape[1]))
      throw dicestack::InputError("ridge: payload does not match the model's dimensions");
    w_.resize(shape[0], shape[1]);
    std::memcpy(w_.data(), payload.data() + sizeof shape, sizeof(double) * static_cast<std::size_t>(w_.size()));
  }

  Eigen::MatrixXd w_;
};

DICESTACK_REGISTER_REGRESSOR(Ridge, "ridge", "ridge regression (closed form, Eigen): an example plugin")
