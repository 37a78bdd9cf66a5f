// Hand-written on Eigen: OpenCV's ANN_MLP trains only by RPROP or plain backprop on full
// batches; the paper's MLP is scikit-learn's MLPRegressor (Adam, mini-batches of 200, L2
// penalty, Glorot initialisation, early stop on a stalled loss), which this reproduces.
#include <algorithm>
#include <cmath>
#include <numeric>

#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

#include "payload.hpp"

namespace dicestack {
namespace {

constexpr int kMaxWidth = 1024;

class Mlp final : public Regressor {
 public:
  using Regressor::Regressor;

  static std::vector<ParamSpec> schema() {
    return {{"layers", ParamType::integer, "5", 1, 64, "hidden layers (paper VI-C: 5)", {}},
            {"width", ParamType::integer, "16", 1, kMaxWidth, "units per hidden layer (paper VI-C: 16)", {}},
            {"max_iter", ParamType::integer, "100", 1, 1e6, "epochs (paper VI-C: 100)", {}},
            {"learning_rate", ParamType::real, "0.001", 1e-12, 10, "Adam step size", {}},
            {"alpha", ParamType::real, "0.0001", 0, 1e6, "L2 penalty", {}},
            {"batch_size", ParamType::integer, "200", 1, 1e7, "rows per Adam step", {}},
            {"tol", ParamType::real, "0.0001", 0, 1e9, "stop when an epoch improves the loss by less, 10 times in a row", {}}};
  }

 private:
  struct Layer {
    Eigen::MatrixXd w;  // out x in
    Eigen::VectorXd b;
  };

  void do_fit(const Matrix& x, const Matrix& y, std::uint64_t seed) override {
    check_width(static_cast<std::size_t>(x.cols()), static_cast<std::size_t>(y.cols()));
    const auto n = x.rows();
    const int hidden = static_cast<int>(params().integer("layers")), width = static_cast<int>(params().integer("width"));
    Rng rng(seed);
    layers_.clear();
    Eigen::Index in = x.cols();
    for (int l = 0; l <= hidden; ++l) {
      const Eigen::Index out = l < hidden ? width : y.cols();
      const double bound = std::sqrt(6.0 / static_cast<double>(in + out));  // Glorot uniform (ReLU: factor 6)
      Layer layer{Eigen::MatrixXd(out, in), Eigen::VectorXd(out)};
      for (Eigen::Index i = 0; i < layer.w.size(); ++i) layer.w.data()[i] = rng.uniform(-bound, bound);
      for (Eigen::Index i = 0; i < layer.b.size(); ++i) layer.b[i] = rng.uniform(-bound, bound);
      layers_.push_back(std::move(layer));
      in = out;
    }
    const double lr = params().real("learning_rate"), alpha = params().real("alpha"), tol = params().real("tol");
    const auto batch = std::min<Eigen::Index>(params().integer("batch_size"), n);
    const double beta1 = 0.9, beta2 = 0.999, adam_eps = 1e-8;
    std::vector<Layer> m1 = zeros_like(), m2 = zeros_like(), grad = zeros_like();
    std::vector<Eigen::MatrixXd> acts(layers_.size() + 1), deltas(layers_.size());
    std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
    std::iota(order.begin(), order.end(), Eigen::Index{0});
    double best = HUGE_VAL, step = 0.0;
    int stale = 0;
    for (long long epoch = 0; epoch < params().integer("max_iter"); ++epoch) {
      for (std::size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
      double loss = 0.0;
      for (Eigen::Index start = 0; start < n; start += batch) {
        const Eigen::Index m = std::min(batch, n - start);
        Eigen::MatrixXd in_rows(x.cols(), m), target(y.cols(), m);  // columns are samples
        for (Eigen::Index c = 0; c < m; ++c) {
          in_rows.col(c) = x.row(order[static_cast<std::size_t>(start + c)]).transpose();
          target.col(c) = y.row(order[static_cast<std::size_t>(start + c)]).transpose();
        }
        acts[0] = std::move(in_rows);
        for (std::size_t l = 0; l < layers_.size(); ++l) {
          acts[l + 1] = (layers_[l].w * acts[l]).colwise() + layers_[l].b;
          if (l + 1 < layers_.size()) acts[l + 1] = acts[l + 1].cwiseMax(0.0);
        }
        const Eigen::MatrixXd err = acts.back() - target;
        loss += 0.5 * err.squaredNorm();
        deltas.back() = err / static_cast<double>(m);
        for (std::size_t l = layers_.size(); l-- > 0;) {
          grad[l].w = deltas[l] * acts[l].transpose() + (alpha / static_cast<double>(m)) * layers_[l].w;
          grad[l].b = deltas[l].rowwise().sum();
          if (l > 0) deltas[l - 1] = (layers_[l].w.transpose() * deltas[l]).cwiseProduct((acts[l].array() > 0.0).cast<double>().matrix());
        }
        step += 1.0;
        const double c1 = 1.0 - std::pow(beta1, step), c2 = 1.0 - std::pow(beta2, step);
        const double rate = lr * std::sqrt(c2) / c1;
        for (std::size_t l = 0; l < layers_.size(); ++l) {
          adam(layers_[l].w, m1[l].w, m2[l].w, grad[l].w, rate, beta1, beta2, adam_eps);
          adam(layers_[l].b, m1[l].b, m2[l].b, grad[l].b, rate, beta1, beta2, adam_eps);
        }
      }
      double penalty = 0.0;
      for (const auto& layer : layers_) penalty += layer.w.squaredNorm();
      loss = (loss + 0.5 * alpha * penalty) / static_cast<double>(n);
      stale = loss > best - tol ? stale + 1 : 0;
      best = std::min(best, loss);
      if (stale >= 10) break;
    }
  }

  template <class M>
  static void adam(M& param, M& m1, M& m2, const M& g, double rate, double beta1, double beta2, double eps) {
    m1 = beta1 * m1 + (1.0 - beta1) * g;
    m2 = beta2 * m2 + (1.0 - beta2) * g.cwiseProduct(g);
    param.array() -= rate * m1.array() / (m2.array().sqrt() + eps);
  }

  std::vector<Layer> zeros_like() const {
    std::vector<Layer> out;
    for (const auto& l : layers_)
      out.push_back({Eigen::MatrixXd::Zero(l.w.rows(), l.w.cols()), Eigen::VectorXd::Zero(l.b.size())});
    return out;
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override {
    double a[kMaxWidth], b[kMaxWidth];  // ping-pong buffers: no allocation per call
    std::copy(x.begin(), x.end(), a);
    Eigen::Index size = static_cast<Eigen::Index>(x.size());
    for (std::size_t l = 0; l < layers_.size(); ++l) {
      const auto& layer = layers_[l];
      Eigen::Map<Eigen::VectorXd> out(b, layer.w.rows());
      out.noalias() = layer.w * Eigen::Map<const Eigen::VectorXd>(a, size) + layer.b;
      if (l + 1 < layers_.size()) out = out.cwiseMax(0.0);
      size = layer.w.rows();
      std::copy(b, b + size, a);
    }
    std::copy(a, a + y.size(), y.begin());
  }

  std::string do_save() const override {
    std::vector<Matrix> store;
    for (const auto& l : layers_) {
      store.emplace_back(l.w);
      store.emplace_back(l.b.transpose());
    }
    std::vector<const Matrix*> ptrs;
    for (const auto& m : store) ptrs.push_back(&m);
    return payload::write_matrices(ptrs);
  }

  // predict_row keeps its rows in kMaxWidth-wide buffers on the stack.
  void check_width(std::size_t inputs, std::size_t outputs) const {
    constexpr auto most = static_cast<std::size_t>(kMaxWidth);
    if (inputs > most || outputs > most)
      throw InputError(name() + ": " + std::to_string(inputs) + " input dimensions and " + std::to_string(outputs) +
                       " outputs; at most " + std::to_string(kMaxWidth) + " of each are supported");
  }

  void do_load(std::string_view text, std::size_t input_dim, std::size_t output_dim) override {
    check_width(input_dim, output_dim);
    const auto count = 2 * static_cast<std::size_t>(params().integer("layers") + 1);
    const auto m = payload::read_matrices(text, count, name());
    std::vector<Layer> layers;
    Eigen::Index in = static_cast<Eigen::Index>(input_dim);
    for (std::size_t i = 0; i < count; i += 2) {
      if (m[i].cols() != in || m[i + 1].rows() != 1 || m[i + 1].cols() != m[i].rows() || m[i].rows() > kMaxWidth)
        throw InputError(name() + ": payload layer shapes do not chain");
      layers.push_back({m[i], m[i + 1].transpose()});
      in = m[i].rows();
    }
    if (static_cast<std::size_t>(in) != output_dim) throw InputError(name() + ": payload output width differs from the header");
    layers_ = std::move(layers);
  }

  std::vector<Layer> layers_;
};

}  // namespace

void register_mlp(RegressorRegistry& r) {
  r.add(regressor_info<Mlp>("mlp", "multi-layer perceptron, ReLU, Adam (as scikit-learn's MLPRegressor); 5 x 16 by default"));
}

}  // namespace dicestack
