// Hand-written on Eigen: OpenCV's SVM solves the dual by SMO, quadratic in the 13,000+ rows of
// a demonstration set; the paper's linear SVR is scikit-learn's SGDRegressor (primal SGD), which
// this reproduces: epsilon-insensitive loss, L2 penalty, inverse-scaling learning rate.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

#include "payload.hpp"

namespace dicestack {
namespace {

class LinearSvr final : public Regressor {
 public:
  using Regressor::Regressor;

  static std::vector<ParamSpec> schema() {
    return {{"epsilon", ParamType::real, "0.001", 0, 1e9, "insensitive-tube half-width, standardised label units (paper VI-C)", {}},
            {"max_iter", ParamType::integer, "2000", 1, 1e7, "most passes over the data (paper VI-C)", {}},
            {"alpha", ParamType::real, "0.0001", 0, 1e9, "L2 penalty", {}},
            {"eta0", ParamType::real, "0.01", 1e-12, 1e9, "initial learning rate", {}},
            {"power_t", ParamType::real, "0.25", 0, 10, "learning rate decays as eta0 / t^power_t", {}},
            {"tol", ParamType::real, "0.001", 0, 1e9, "stop when a pass improves the loss by less, 5 times in a row", {}}};
  }

 private:
  void do_fit(const Matrix& x, const Matrix& y, std::uint64_t seed) override {
    const auto n = x.rows(), d = x.cols(), k = y.cols();
    w_ = Matrix::Zero(k, d + 1);  // last column: intercept
    const double eps = params().real("epsilon"), alpha = params().real("alpha"), eta0 = params().real("eta0");
    const double power_t = params().real("power_t"), tol = params().real("tol");
    const auto max_iter = params().integer("max_iter");
    std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
    for (Eigen::Index j = 0; j < k; ++j) {  // one model per output, as MultiOutputRegressor
      Rng rng(derive_seed(seed, static_cast<std::uint64_t>(j)));
      Eigen::VectorXd w = Eigen::VectorXd::Zero(d);
      double b = 0.0, t = 1.0, best = HUGE_VAL;
      int stale = 0;
      std::iota(order.begin(), order.end(), Eigen::Index{0});
      for (long long epoch = 0; epoch < max_iter; ++epoch) {
        for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
        double loss = 0.0;
        for (const Eigen::Index i : order) {
          const double eta = eta0 / std::pow(t, power_t);
          const double r = y(i, j) - (x.row(i).dot(w) + b);
          loss += std::max(0.0, std::abs(r) - eps);
          w *= 1.0 - eta * alpha;
          if (r > eps) {
            w += eta * x.row(i).transpose();
            b += eta;
          } else if (r < -eps) {
            w -= eta * x.row(i).transpose();
            b -= eta;
          }
          t += 1.0;
        }
        loss = loss / static_cast<double>(n) + 0.5 * alpha * w.squaredNorm();
        stale = loss > best - tol ? stale + 1 : 0;
        best = std::min(best, loss);
        if (stale >= 5) break;
      }
      w_.row(j).head(d) = w.transpose();
      w_(j, d) = b;
    }
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override {
    const auto d = static_cast<Eigen::Index>(x.size());
    const Eigen::Map<const Eigen::RowVectorXd> row(x.data(), d);
    for (std::size_t j = 0; j < y.size(); ++j)
      y[j] = w_.row(static_cast<Eigen::Index>(j)).head(d).dot(row) + w_(static_cast<Eigen::Index>(j), d);
  }

  std::string do_save() const override { return payload::write_matrices({&w_}); }

  void do_load(std::string_view text, std::size_t input_dim, std::size_t output_dim) override {
    auto m = payload::read_matrices(text, 1, name());
    if (static_cast<std::size_t>(m[0].rows()) != output_dim || static_cast<std::size_t>(m[0].cols()) != input_dim + 1)
      throw InputError(name() + ": payload weights do not match the header's dimensions");
    w_ = std::move(m[0]);
  }

  Matrix w_;
};

}  // namespace

void register_linear_svr(RegressorRegistry& r) {
  r.add(regressor_info<LinearSvr>(
      "linear_svr", "epsilon-insensitive linear SVR fitted by SGD (as scikit-learn's SGDRegressor), one per action"));
}

}  // namespace dicestack
