#pragma once
// Exact k nearest neighbours for wide rows (knn at dart's 49 inputs). A tree of clusters: each
// node splits its rows in two as 2-means would, starting from the median along their principal
// direction, and keeps their bounding box; the search skips a node whose box lies farther than
// the k-th row found, and in a leaf a row whose distance to the leaf's centre says it must.
// Why not a k-d tree: its cells, cut along one coordinate at a time, fit trajectory rows badly
// and its search visited most leaves (docs/regressors.md, "knn at any width").
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include <Eigen/Core>

namespace dicestack {

class ClusterTree {
 public:
  using Rows = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  enum class Metric { l2, l1 };
  static constexpr std::size_t kMaxCols = 64;

  /// Builds the tree over `rows` (deterministic: no random choice; at most kMaxCols columns,
  /// else std::invalid_argument). The rows are stored in the tree's leaf order: order()[i] is
  /// the input index of stored row i.
  ClusterTree(Rows rows, Metric metric, std::size_t leaf_size);

  /// The k (<= rows) nearest stored rows to `query` (cols() floats), nearest first: their
  /// stored indices and distances (squared under l2). Of rows at equal distance, the earlier
  /// input row is nearer, so the answer does not depend on the tree. Every distance is summed
  /// in one fixed order (8 lanes, then the lanes pairwise), so the answer does not depend on
  /// the CPU either: the AVX2 and the baseline code give the same bits. Never allocates;
  /// thread-safe.
  std::size_t search(const float* query, std::size_t k, std::size_t* index, float* distance) const;

  /// The distance search() computes between two rows of cols() floats (squared under l2):
  /// what a brute-force search must compute to find the same rows bit for bit.
  float row_distance(const float* a, const float* b) const;

  const std::vector<std::size_t>& order() const { return order_; }
  std::size_t cols() const { return cols_; }

 private:
  struct Node {
    std::uint32_t begin, end;  // stored rows [begin, end)
    std::uint32_t left = 0, right = 0;  // children (0: a leaf; the root is never a child)
    float radius = 0.0f;  // the farthest of its rows from its centre (metric distance)
  };
  struct Free {
    void operator()(void* p) const { std::free(p); }
  };
  template <class T>
  using Aligned = std::unique_ptr<T[], Free>;  // 64-byte aligned
  class Best;

  std::uint32_t build(Rows& rows, std::uint32_t begin, std::uint32_t end, std::vector<float>& centres, std::vector<float>& boxes);
  void visit(std::uint32_t node, float lower_bound, const float* query, Best& best) const;
  void scan_leaf(std::uint32_t node, const float* query, Best& best) const;
  void children_bounds(std::uint32_t node, const float* query, float* bounds) const;  // to the two children's boxes
  float distance(const float* a, const float* b) const;  // metric distance (not squared), padded rows
  const float* row(std::size_t i) const { return rows_.get() + i * stride_; }
  const float* centre(std::uint32_t node) const { return centres_.get() + static_cast<std::size_t>(node) * stride_; }
  const std::uint16_t* children_boxes(std::uint32_t node) const { return boxes_.get() + 4 * static_cast<std::size_t>(node) * stride_; }

  std::size_t cols_, stride_;  // stride_: cols_ rounded up to 8 lanes; the padding is zeros
  Metric metric_;
  std::size_t leaf_size_;
  std::vector<std::size_t> order_;
  std::vector<Node> nodes_;
  Aligned<float> rows_;     // the stored rows, padded to stride_
  Aligned<float> centres_;  // per node: the mean of its rows
  Aligned<std::uint16_t> boxes_;  // per inner node: its children's boxes (bfloat16, rounded outwards),
                                  // each the least then the greatest value of each column
  std::vector<float> to_centre_;  // each stored row's distance to its leaf's centre
};

}  // namespace dicestack
