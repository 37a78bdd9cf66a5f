#include <algorithm>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <variant>

#include <Eigen/Eigenvalues>
#include <nanoflann.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/regressors/registry.hpp>

#include "cluster_tree.hpp"
#include "payload.hpp"

namespace dicestack {
namespace {

// The tree searches single-precision rows: half the memory traffic (measured predict_row
// 13.8 -> 12.1 us on the 14,541 human training rows); the labels stay double.
using FloatRows = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// nanoflann reads the training rows in place through this adaptor: nothing is copied.
struct RowsAdaptor {
  const FloatRows* rows;
  std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(rows->rows()); }
  float kdtree_get_pt(std::size_t i, std::size_t d) const {
    return (*rows)(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(d));
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};

// A fixed dimension keeps nanoflann's per-query scratch on the stack (no allocation); 24 is
// the state size, anything else uses the dynamic-size tree.
template <class Metric, int Dim>
using Tree = nanoflann::KDTreeSingleIndexAdaptor<Metric, RowsAdaptor, Dim, std::size_t>;
template <int Dim>
using L2Tree = Tree<nanoflann::L2_Simple_Adaptor<float, RowsAdaptor, float, std::size_t>, Dim>;
template <int Dim>
using L1Tree = Tree<nanoflann::L1_Adaptor<float, RowsAdaptor, float, std::size_t>, Dim>;

constexpr int kMaxK = 64;
constexpr Eigen::Index kMaxDim = 64;  // predict_row's query lives on the stack

// k nearest neighbours over the standardised states; the prediction is the mean of the k
// labels (uniform weights, as scikit-learn's KNeighborsRegressor by default).
class Knn final : public Regressor {
 public:
  using Regressor::Regressor;

  static std::vector<ParamSpec> schema() {
    return {{"k", ParamType::integer, "3", 1, kMaxK, "neighbours averaged (paper VI-E2: 3)", {}},
            {"metric", ParamType::choice, "l2", 0, 0, "distance on standardised states: l2 (Euclidean) or l1", {"l2", "l1"}},
            {"leaf_size", ParamType::integer, "20", 1, 10000, "tree leaf size (speed only)", {}},
            {"search", ParamType::choice, "cluster_tree", 0, 0,
             "cluster_tree (2-means clusters, eight bounding boxes a node: 5-35x faster than kdtree on held-out states and rollouts at 24 and 49 inputs; docs/regressors.md) or kdtree (nanoflann); exact either way, "
             "equal distances: the earlier training row (cluster_tree) or the tree's order (kdtree)",
             {"cluster_tree", "kdtree"}},
            {"rotate", ParamType::boolean, "true", 0, 0, "kdtree, l2: search along the states' principal axes (speed only; the search is exact either way)", {}}};
  }

 private:
  void do_fit(const Matrix& x, const Matrix& y, std::uint64_t) override {
    x_ = x;
    y_ = y;
    build();
  }

  void build() {
    if (x_.cols() > kMaxDim)
      throw InputError(name() + ": " + std::to_string(x_.cols()) + " input dimensions; at most " + std::to_string(kMaxDim) +
                       " are supported");
    if (use_cluster_tree()) {
      // Its node ids are 32 bits and a tree of N rows has up to 2N - 1 nodes.
      if (x_.rows() > std::numeric_limits<std::int32_t>::max())
        throw InputError(name() + ": " + std::to_string(x_.rows()) +
                         " training rows; search=cluster_tree takes at most 2147483647 (search=kdtree has no such bound)");
      build_cluster_tree();
      return;
    }
    rotate();
    xf_.resize(x_.rows(), x_.cols());  // row by row: no full-size temporaries (fit time)
    const Eigen::RowVectorXd centre = centre_.transpose();
    for (Eigen::Index i = 0; i < x_.rows(); ++i) xf_.row(i) = ((x_.row(i) - centre) * axes_).cast<float>();
    adaptor_ = {&xf_};
    make_tree();
    // Measured: predict_row spent most of its time on cache misses, reading the rows of a leaf
    // from all over memory. Store the rows in the tree's leaf order and point the tree at them
    // in place: each leaf's rows then sit together, the tree is the same (a second build on
    // the sorted rows would give this tree again, at twice the fit time).
    std::vector<std::size_t>& order = std::visit(
        [](auto& t) -> std::vector<std::size_t>& {
          if constexpr (std::is_same_v<std::decay_t<decltype(*t)>, ClusterTree>) throw std::logic_error("not a k-d tree");
          else return t->vAcc;
        },
        tree_);
    FloatRows sorted(xf_.rows(), xf_.cols());
    labels_.resize(y_.rows(), y_.cols());
    for (std::size_t i = 0; i < order.size(); ++i) {
      sorted.row(static_cast<Eigen::Index>(i)) = xf_.row(static_cast<Eigen::Index>(order[i]));
      labels_.row(static_cast<Eigen::Index>(i)) = y_.row(static_cast<Eigen::Index>(order[i]));
      order[i] = i;
    }
    xf_ = std::move(sorted);  // the adaptor points at xf_, which now holds the sorted rows
  }

  bool use_cluster_tree() const { return params().choice("search") == "cluster_tree"; }

  void build_cluster_tree() {
    // Not rotated: measured, boxes along the principal axes prune worse (300 against 125 us per
    // rollout step under dart's map, whose start columns are constant within an episode).
    centre_ = x_.colwise().mean().transpose();
    ClusterTree::Rows rows(x_.rows(), x_.cols());  // centred: float keeps more of each difference
    const Eigen::RowVectorXd centre = centre_.transpose();
    for (Eigen::Index i = 0; i < x_.rows(); ++i) rows.row(i) = (x_.row(i) - centre).cast<float>();
    const auto metric = params().choice("metric") == "l1" ? ClusterTree::Metric::l1 : ClusterTree::Metric::l2;
    tree_.emplace<std::unique_ptr<ClusterTree>>(
        std::make_unique<ClusterTree>(std::move(rows), metric, static_cast<std::size_t>(params().integer("leaf_size"))));
    const auto& order = std::get<std::unique_ptr<ClusterTree>>(tree_)->order();
    labels_.resize(y_.rows(), y_.cols());
    for (std::size_t i = 0; i < order.size(); ++i)
      labels_.row(static_cast<Eigen::Index>(i)) = y_.row(static_cast<Eigen::Index>(order[i]));
  }

  // A k-d tree splits along coordinate axes; the 24 state dimensions are strongly correlated
  // (dice in the cup move with it), so the cells are long and thin across the data and the
  // search visits many leaves. Rotating to the principal axes (largest variance first) keeps
  // every L2 distance and makes the cells fit the data. L1 distances are not rotation
  // invariant: that metric searches the states as given.
  void rotate() {
    const auto d = x_.cols();
    centre_ = x_.colwise().mean().transpose();
    axes_ = Matrix::Identity(d, d);
    if (params().choice("metric") != "l2" || !params().boolean("rotate") || x_.rows() < 2) return;
    Matrix scatter = x_.transpose() * x_;  // of the centred rows, without copying them
    scatter -= static_cast<double>(x_.rows()) * centre_ * centre_.transpose();
    const Eigen::SelfAdjointEigenSolver<Matrix> eig(scatter);
    axes_ = eig.eigenvectors().rowwise().reverse();  // descending variance
  }

  void make_tree() {
    const auto leaf = static_cast<std::size_t>(params().integer("leaf_size"));
    const bool l1 = params().choice("metric") == "l1";
    const auto dims = static_cast<std::size_t>(x_.cols());
    const nanoflann::KDTreeSingleIndexAdaptorParams p(leaf);  // the constructors build the tree
    if (dims == 24) {
      if (l1) tree_.emplace<std::unique_ptr<L1Tree<24>>>(std::make_unique<L1Tree<24>>(dims, adaptor_, p));
      else tree_.emplace<std::unique_ptr<L2Tree<24>>>(std::make_unique<L2Tree<24>>(dims, adaptor_, p));
    } else {
      if (l1) tree_.emplace<std::unique_ptr<L1Tree<-1>>>(std::make_unique<L1Tree<-1>>(dims, adaptor_, p));
      else tree_.emplace<std::unique_ptr<L2Tree<-1>>>(std::make_unique<L2Tree<-1>>(dims, adaptor_, p));
    }
  }

  void do_predict_row(std::span<const double> x, std::span<double> y) const override {
    const auto k = std::min<std::size_t>(static_cast<std::size_t>(params().integer("k")), static_cast<std::size_t>(x_.rows()));
    std::size_t idx[kMaxK];
    float dist[kMaxK], query[kMaxDim];
    const auto d = static_cast<Eigen::Index>(x.size());
    if (std::holds_alternative<std::unique_ptr<ClusterTree>>(tree_)) {
      for (Eigen::Index j = 0; j < d; ++j) query[j] = static_cast<float>(x[static_cast<std::size_t>(j)] - centre_(j));
    } else {
      double rotated[kMaxDim] = {};
      for (Eigen::Index i = 0; i < d; ++i) {  // (x - centre) * axes, one row of axes at a time
        const double c = x[static_cast<std::size_t>(i)] - centre_(i);
        for (Eigen::Index j = 0; j < d; ++j) rotated[j] += c * axes_(i, j);
      }
      for (Eigen::Index j = 0; j < d; ++j) query[j] = static_cast<float>(rotated[j]);
    }
    const std::size_t found = std::visit(
        [&](const auto& t) {
          if constexpr (std::is_same_v<std::decay_t<decltype(*t)>, ClusterTree>) return t->search(query, k, idx, dist);
          else return t->knnSearch(query, k, idx, dist);
        },
        tree_);
    std::fill(y.begin(), y.end(), 0.0);
    for (std::size_t n = 0; n < found; ++n)
      for (std::size_t j = 0; j < y.size(); ++j) y[j] += labels_(static_cast<Eigen::Index>(idx[n]), static_cast<Eigen::Index>(j));
    for (double& v : y) v /= static_cast<double>(found);
  }

  std::string do_save() const override { return payload::write_matrices({&x_, &y_}); }

  void do_load(std::string_view text, std::size_t input_dim, std::size_t output_dim) override {
    auto m = payload::read_matrices(text, 2, name());
    if (static_cast<std::size_t>(m[0].cols()) != input_dim || static_cast<std::size_t>(m[1].cols()) != output_dim ||
        m[0].rows() != m[1].rows() || m[0].rows() == 0)
      throw InputError(name() + ": payload holds " + std::to_string(m[0].rows()) + " x " + std::to_string(m[0].cols()) +
                       " inputs and " + std::to_string(m[1].rows()) + " x " + std::to_string(m[1].cols()) +
                       " labels, not matching the header");
    x_ = std::move(m[0]);
    y_ = std::move(m[1]);
    build();
  }

  Matrix x_, y_;  // saved as given
  Eigen::VectorXd centre_;  // column means of x_
  Matrix axes_;    // kdtree: principal axes as columns (identity when not rotating)
  FloatRows xf_;   // kdtree: (x_ - centre_) * axes_, what it searches, in its leaf order
  Matrix labels_; // y_ in the same order
  RowsAdaptor adaptor_{nullptr};
  std::variant<std::unique_ptr<L2Tree<24>>, std::unique_ptr<L1Tree<24>>, std::unique_ptr<L2Tree<-1>>,
               std::unique_ptr<L1Tree<-1>>, std::unique_ptr<ClusterTree>>
      tree_;
};

}  // namespace

void register_knn(RegressorRegistry& r) {
  r.add(regressor_info<Knn>("knn", "k nearest neighbours (exact: a cluster tree, or nanoflann's k-d tree) over standardised states; mean of the k labels"));
}

}  // namespace dicestack
