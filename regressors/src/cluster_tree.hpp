#pragma once
// Exact k nearest neighbours for wide rows (knn at dart's 49 inputs). A tree of clusters: each
// split divides its rows in two as 2-means would, starting from the median along their
// principal direction; three levels of splits make one search node of up to eight children,
// whose bounding boxes it keeps column by column, so that one pass over the columns bounds all
// eight in the lanes of one vector. The search takes the node with the nearest box first and
// skips every box that lies farther than the k-th row found.
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

  /// The k (<= rows) nearest stored rows to `query` (as many floats as a row), nearest first:
  /// their stored indices and distances (squared under l2). Of rows at equal distance, the
  /// earlier input row is nearer, so the answer does not depend on the tree. A distance is
  /// summed in one fixed order: the float differences' squares (l1: magnitudes) in 8 lanes,
  /// lane i summing columns i, i + 8, ... in order, then the lanes as ((0 + 4) + (2 + 6)) +
  /// ((1 + 5) + (3 + 7)), with no fused multiply-add; the AVX2 and the baseline x86-64 code do
  /// the same arithmetic lane by lane, so the answer does not depend on the CPU either. Never
  /// allocates; thread-safe.
  std::size_t search(const float* query, std::size_t k, std::size_t* index, float* distance) const;

  const std::vector<std::size_t>& order() const { return order_; }

 private:
  static constexpr std::size_t kFan = 8;  // children per search node: the vector lanes
  static constexpr std::uint32_t kLeaf = 0x80000000u;  // a child reference with this bit is a leaf
  struct Split;  // a node of the binary tree the build makes
  struct Node {
    std::uint32_t child[kFan];  // a node's index, or kLeaf | a leaf's index
    std::uint32_t children;
  };
  struct Leaf {
    std::uint32_t begin, end;  // stored rows [begin, end)
  };
  struct Free {
    void operator()(void* p) const { std::free(p); }
  };
  template <class T>
  using Aligned = std::unique_ptr<T[], Free>;  // 64-byte aligned
  class Best;

  std::uint32_t split(Rows& rows, std::uint32_t begin, std::uint32_t end, std::vector<Split>& splits, std::vector<float>& boxes);
  std::uint32_t widen(const std::vector<Split>& splits, const std::vector<float>& boxes, std::uint32_t split,
                      std::vector<float>& wide_boxes);
  void visit(std::uint32_t child, float bound, const float* query, Best& best) const;
  void scan(const Leaf& leaf, const float* query, Best& best) const;
  void bounds(std::uint32_t node, const float* query, float* out) const;  // to each child's box
  const float* row(std::size_t i) const { return rows_.get() + i * stride_; }

  std::size_t cols_, stride_;  // stride_: cols_ rounded up to 8 lanes; the padding is zeros
  Metric metric_;
  std::size_t leaf_size_;
  std::vector<std::size_t> order_;
  std::vector<Node> nodes_;  // the root is nodes_[0] (none when all rows make one leaf)
  std::vector<Leaf> leaves_;
  Aligned<float> rows_;   // the stored rows, padded to stride_
  Aligned<float> boxes_;  // per node, per column: its children's box centres, then half-widths
};

}  // namespace dicestack
