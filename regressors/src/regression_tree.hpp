#pragma once
// CART regression trees for `random_forest`: exact best splits (least squares) on features
// sorted once per fit, bootstrap weights, nodes in one flat array.
#include <span>
#include <string>
#include <vector>

#include <dicestack/core/matrix.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack::forest {

/// A split (feature >= 0: go to `left` if x[feature] <= threshold, else `right`) or a leaf
/// (feature == -1) predicting `value`. Children always come after their parent.
struct Node {
  int feature = -1;
  double threshold = 0.0;
  int left = -1, right = -1;
  double value = 0.0;
};

using Tree = std::vector<Node>;

/// Every feature's row order (ascending, ties by row), computed once and shared by all trees.
class SortedColumns {
 public:
  explicit SortedColumns(const Matrix& x);
  std::span<const int> order(Eigen::Index feature) const;

 private:
  std::vector<int> order_;  // feature-major: rows of feature f at [f * n, (f + 1) * n)
  Eigen::Index rows_ = 0;
};

struct TreeOptions {
  int max_depth = 12;
  int min_samples = 2;  ///< fewest distinct rows a node needs to split
  int features = 0;     ///< features tried per split, drawn per node; 0 means all
};

/// Grows one tree predicting `y` from `x`, row i counted `weights[i]` times (a bootstrap
/// sample; 0 leaves the row out). Draws the features tried at each node from `rng`.
Tree grow_tree(const Matrix& x, std::span<const double> y, const SortedColumns& sorted, std::span<const int> weights,
               const TreeOptions& options, Rng& rng);

/// The leaf value the row reaches.
inline double predict(const Tree& tree, const double* x) {
  int at = 0;
  while (tree[static_cast<std::size_t>(at)].feature >= 0) {
    const Node& n = tree[static_cast<std::size_t>(at)];
    at = x[n.feature] <= n.threshold ? n.left : n.right;
  }
  return tree[static_cast<std::size_t>(at)].value;
}

/// Trees as one matrix of rows (feature, threshold, left, right, value), and back; `check`
/// rejects a stored tree that could index out of range or loop, naming `who`.
Matrix to_matrix(const std::vector<Tree>& trees);
std::vector<Tree> from_matrix(const Matrix& nodes, std::span<const double> sizes, std::size_t inputs, const std::string& who);

}  // namespace dicestack::forest
