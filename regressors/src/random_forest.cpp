#include <algorithm>

#include <dicestack/core/error.hpp>
#include <dicestack/core/parallel.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/registry.hpp>

#include "payload.hpp"
#include "regression_tree.hpp"

namespace dicestack {
namespace {

// Bootstrap regression trees, one forest per action (a tree fitted to one action fits it
// better than a tree shared by all three: test error 0.474 against scikit-learn's shared
// trees' 0.542 on the recordings). Our own trees, not OpenCV's RTrees: those sort every
// node's rows again and fitted 4.4x slower than scikit-learn (6.8 s against 1.5 s).
class RandomForest final : public Regressor {
 public:
  using Regressor::Regressor;

  static std::vector<ParamSpec> schema() {
    return {{"trees", ParamType::integer, "8", 1, 100000, "number of trees (paper VI-C: 8)", {}},
            {"max_depth", ParamType::integer, "12", 1, 64, "deepest split (paper VI-C: 12)", {}},
            {"min_samples", ParamType::integer, "2", 1, 1e9, "fewest rows a node needs to split", {}},
            {"features", ParamType::integer, "0", 0, 1e6, "features tried per split; 0 means all (scikit-learn's default)", {}},
            {"threads", ParamType::integer, "0", 0, 1024, "training threads, 0 = all cores (the model is the same for any)", {}}};
  }

 private:
  void do_fit(const Matrix& x, const Matrix& y, std::uint64_t seed) override {
    const auto features = params().integer("features");
    if (features > x.cols())
      throw InputError(name() + ": parameter features = " + std::to_string(features) + " exceeds the " +
                       std::to_string(x.cols()) + " input columns");
    const forest::TreeOptions options{static_cast<int>(params().integer("max_depth")),
                                      static_cast<int>(params().integer("min_samples")), static_cast<int>(features)};
    const auto per_output = static_cast<std::size_t>(params().integer("trees"));
    const forest::SortedColumns sorted(x);
    std::vector<Eigen::VectorXd> labels;
    for (Eigen::Index j = 0; j < y.cols(); ++j) labels.emplace_back(y.col(j));
    std::vector<forest::Tree> trees(per_output * static_cast<std::size_t>(y.cols()));
    // Tree i draws from its own stream: the forest is the same on any number of threads.
    parallel_for(trees.size(), static_cast<int>(params().integer("threads")), [&](std::size_t i, int) {
      Rng rng(derive_seed(seed, i));
      std::vector<int> weights(static_cast<std::size_t>(x.rows()), 0);
      for (Eigen::Index k = 0; k < x.rows(); ++k) ++weights[rng.below(static_cast<std::uint64_t>(x.rows()))];
      const auto& col = labels[i / per_output];
      trees[i] = forest::grow_tree(x, {col.data(), static_cast<std::size_t>(col.size())}, sorted, weights, options, rng);
    });
    trees_ = std::move(trees);
    per_output_ = per_output;
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override {
    // Blocks of trees walked a level at a time (their cache misses overlap), summed in tree order.
    constexpr std::size_t kBlock = 16;
    const forest::Node* at[kBlock];
    for (std::size_t j = 0; j < y.size(); ++j) {
      double sum = 0.0;
      for (std::size_t begin = 0; begin < per_output_; begin += kBlock) {
        const std::size_t n = std::min(kBlock, per_output_ - begin);
        for (std::size_t i = 0; i < n; ++i) at[i] = trees_[j * per_output_ + begin + i].data();
        for (bool moving = true; moving;) {
          moving = false;
          for (std::size_t i = 0; i < n; ++i) {
            const forest::Node& node = *at[i];
            if (node.feature < 0) continue;
            const forest::Node* tree = trees_[j * per_output_ + begin + i].data();
            at[i] = tree + (x[static_cast<std::size_t>(node.feature)] <= node.threshold ? node.left : node.right);
            moving = true;
          }
        }
        for (std::size_t i = 0; i < n; ++i) sum += at[i]->value;
      }
      y[j] = sum / static_cast<double>(per_output_);
    }
  }

  std::string do_save() const override {
    Matrix sizes(1, static_cast<Eigen::Index>(trees_.size()));
    for (std::size_t i = 0; i < trees_.size(); ++i) sizes(0, static_cast<Eigen::Index>(i)) = static_cast<double>(trees_[i].size());
    const Matrix nodes = forest::to_matrix(trees_);
    return payload::write_matrices({&sizes, &nodes});
  }

  void do_load(std::string_view payload, std::size_t inputs, std::size_t outputs) override {
    const auto m = payload::read_matrices(payload, 2, name());
    const auto count = static_cast<std::size_t>(m[0].size());
    if (m[0].rows() != 1 || count == 0 || count % outputs != 0 || m[1].cols() != 5)
      throw InputError(name() + ": model payload holds " + std::to_string(count) + " trees for " + std::to_string(outputs) +
                       " outputs (a multiple was expected) and nodes of " + std::to_string(m[1].cols()) + " columns (5 expected)");
    trees_ = forest::from_matrix(m[1], {m[0].data(), count}, inputs, name());
    per_output_ = count / outputs;
  }

  std::vector<forest::Tree> trees_;  // output j's trees at [j * per_output_, (j + 1) * per_output_)
  std::size_t per_output_ = 0;
};

}  // namespace

void register_random_forest(RegressorRegistry& r) {
  r.add(regressor_info<RandomForest>("random_forest", "random forest of regression trees (exact least-squares splits), one forest per action"));
}

}  // namespace dicestack
