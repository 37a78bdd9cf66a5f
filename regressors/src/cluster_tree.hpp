#pragma once
// Exact k nearest neighbours for wide rows (knn at dart's 49 inputs). A tree of clusters: each
// node splits its rows in two as 2-means would, starting from the median along their principal
// direction, and keeps their bounding box; the search skips a node whose box lies farther than
// the k-th row found, and in a leaf a row whose distance to the leaf's centre says it must.
// Why not a k-d tree: its cells, cut along one coordinate at a time, fit trajectory rows badly
// and its search visited most leaves (docs/regressors.md, "knn at any width").
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace dicestack {

class ClusterTree {
 public:
  using Rows = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  enum class Metric { l2, l1 };

  /// Builds the tree over `rows` (deterministic: no random choice). The rows are stored in the
  /// tree's leaf order: order()[i] is the input index of stored row i.
  ClusterTree(Rows rows, Metric metric, std::size_t leaf_size);

  /// The k (<= rows) nearest stored rows to `query` (cols() floats), nearest first: their
  /// stored indices and distances (squared under l2). Of rows at equal distance, the earlier
  /// input row is nearer, so the answer does not depend on the tree. Never allocates;
  /// thread-safe.
  std::size_t search(const float* query, std::size_t k, std::size_t* index, float* distance) const;

  const std::vector<std::size_t>& order() const { return order_; }

 private:
  struct Node {
    std::uint32_t begin, end;  // stored rows [begin, end)
    std::uint32_t left = 0, right = 0;  // children (0: a leaf; the root is never a child)
    float radius = 0.0f;  // the farthest of its rows from its centre (metric distance)
  };
  class Best;

  std::uint32_t build(std::uint32_t begin, std::uint32_t end);
  void visit(std::uint32_t node, float lower_bound, const float* query, Best& best) const;
  float box_distance(std::uint32_t node, const float* query) const;  // to the node's bounding box
  float distance(const float* a, const float* b) const;  // metric distance (not squared)
  const float* centre(std::uint32_t node) const { return centres_.data() + static_cast<std::size_t>(node) * cols(); }
  const float* box(std::uint32_t node) const { return boxes_.data() + 2 * static_cast<std::size_t>(node) * cols(); }
  std::size_t cols() const { return static_cast<std::size_t>(rows_.cols()); }

  Rows rows_;
  Metric metric_;
  std::size_t leaf_size_;
  std::vector<std::size_t> order_;
  std::vector<Node> nodes_;
  std::vector<float> centres_;    // one row per node: the mean of its rows
  std::vector<float> boxes_;      // per node: the least then the greatest value of each column
  std::vector<float> to_centre_;  // each stored row's distance to its leaf's centre
};

}  // namespace dicestack
