#include "regression_tree.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <dicestack/core/error.hpp>

namespace dicestack::forest {

SortedColumns::SortedColumns(const Matrix& x) : order_(static_cast<std::size_t>(x.size())), rows_(x.rows()) {
  const auto n = static_cast<std::size_t>(rows_);
  for (Eigen::Index f = 0; f < x.cols(); ++f) {
    const auto first = order_.begin() + static_cast<std::ptrdiff_t>(static_cast<std::size_t>(f) * n);
    std::iota(first, first + static_cast<std::ptrdiff_t>(n), 0);
    std::stable_sort(first, first + static_cast<std::ptrdiff_t>(n), [&](int a, int b) { return x(a, f) < x(b, f); });
  }
}

std::span<const int> SortedColumns::order(Eigen::Index feature) const {
  return {order_.data() + static_cast<std::size_t>(feature * rows_), static_cast<std::size_t>(rows_)};
}

namespace {

// A node waiting to be grown: its rows are [begin, end) of every feature's segment.
struct Pending {
  int node, begin, end, depth;
};

struct Split {
  int feature = -1, last_left = -1;  // position (in the feature's segment) of the last row going left
  double score = 0.0;                // sum_left^2 / w_left + sum_right^2 / w_right
};

// In-bag rows of each feature in that feature's order, feature after feature.
std::vector<int> in_bag_rows(const SortedColumns& sorted, int d, std::span<const int> weights) {
  std::vector<int> rows;
  for (int f = 0; f < d; ++f)
    for (const int r : sorted.order(f))
      if (weights[static_cast<std::size_t>(r)] > 0) rows.push_back(r);
  return rows;
}

// What growing one tree reads: the data, the bootstrap weights, and the in-bag rows of every
// feature (`m` per feature, in_bag_rows' layout).
struct GrowContext {
  const Matrix& x;
  std::span<const double> y;
  std::span<const int> weights;
  std::vector<int> rows;
  int m;
  int* segment(int f) { return rows.data() + static_cast<std::size_t>(f) * static_cast<std::size_t>(m); }
  const int* segment(int f) const { return rows.data() + static_cast<std::size_t>(f) * static_cast<std::size_t>(m); }
};

// A node's weight w, weighted label sum s and weighted sum of squared labels q.
struct NodeSums {
  double w = 0.0, s = 0.0, q = 0.0;
};

NodeSums sum_node(const GrowContext& g, const Pending& p) {
  NodeSums sums;
  for (int k = p.begin; k < p.end; ++k) {
    const int r = g.segment(0)[k];
    const double c = g.weights[static_cast<std::size_t>(r)], v = g.y[static_cast<std::size_t>(r)];
    sums.w += c;
    sums.s += c * v;
    sums.q += c * v * v;
  }
  return sums;
}

// Draws the `tries` features a node tries into the front of `candidates` (partial Fisher-Yates).
void draw_features(std::vector<int>& candidates, int tries, int d, Rng& rng) {
  for (int i = 0; i < tries; ++i)
    std::swap(candidates[static_cast<std::size_t>(i)],
              candidates[static_cast<std::size_t>(i) + rng.below(static_cast<std::uint64_t>(d - i))]);
}

// The best split of node `p` on the first `tries` candidates, or feature -1 when none scores
// above the unsplit node's `parent` score.
Split best_split(const GrowContext& g, const Pending& p, const std::vector<int>& candidates, int tries, const NodeSums& sums,
                 double parent) {
  Split best{-1, -1, parent};
  for (int t = 0; t < tries; ++t) {
    const int f = candidates[static_cast<std::size_t>(t)];
    const int* seg = g.segment(f);
    double wl = 0.0, sl = 0.0;
    for (int k = p.begin; k + 1 < p.end; ++k) {
      const int r = seg[k];
      const double c = g.weights[static_cast<std::size_t>(r)];
      wl += c;
      sl += c * g.y[static_cast<std::size_t>(r)];
      if (!(g.x(seg[k + 1], f) > g.x(r, f))) continue;  // no threshold between equal values
      const double sr = sums.s - sl, score = sl * sl / wl + sr * sr / (sums.w - wl);
      if (score > best.score) best = {f, k, score};
    }
  }
  return best;
}

// The threshold between the last row going left and the next one.
double split_threshold(const GrowContext& g, const Split& best) {
  const int* seg = g.segment(best.feature);
  const double lo = g.x(seg[best.last_left], best.feature), hi = g.x(seg[best.last_left + 1], best.feature);
  double threshold = lo + 0.5 * (hi - lo);
  if (!(threshold < hi)) threshold = lo;  // adjacent doubles: the midpoint rounds up to hi
  return threshold;
}

// Partitions node p's part of every feature's segment stably into the rows going left, then
// those going right, so each child's rows stay sorted without sorting again.
void partition_segments(GrowContext& g, const Pending& p, const Split& best, int d, std::vector<char>& goes_left,
                        std::vector<int>& scratch) {
  const int* seg = g.segment(best.feature);
  for (int k = p.begin; k < p.end; ++k) goes_left[static_cast<std::size_t>(seg[k])] = k <= best.last_left;
  for (int f = 0; f < d; ++f) {
    int* h = g.segment(f);
    int l = p.begin, spilled = 0;
    for (int k = p.begin; k < p.end; ++k)
      if (goes_left[static_cast<std::size_t>(h[k])]) h[l++] = h[k];
      else scratch[static_cast<std::size_t>(spilled++)] = h[k];
    std::copy(scratch.begin(), scratch.begin() + spilled, h + l);
  }
}

}  // namespace

Tree grow_tree(const Matrix& x, std::span<const double> y, const SortedColumns& sorted, std::span<const int> weights,
               const TreeOptions& options, Rng& rng) {
  const int d = static_cast<int>(x.cols());
  // Splitting a node partitions every feature's segment stably, so each child's rows stay
  // sorted without sorting again.
  std::vector<int> rows = in_bag_rows(sorted, d, weights);
  const int m = d > 0 ? static_cast<int>(rows.size()) / d : 0;
  Tree tree(1);
  if (m == 0) return tree;  // nothing in the bag: a single leaf predicting 0

  GrowContext g{x, y, weights, std::move(rows), m};
  std::vector<char> goes_left(static_cast<std::size_t>(x.rows()), 0);
  std::vector<int> scratch(static_cast<std::size_t>(m));
  std::vector<int> candidates(static_cast<std::size_t>(d));
  std::iota(candidates.begin(), candidates.end(), 0);
  const int tries = options.features > 0 ? std::min(options.features, d) : d;

  std::vector<Pending> stack{{0, 0, m, 0}};
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    const NodeSums sums = sum_node(g, p);
    tree[static_cast<std::size_t>(p.node)].value = sums.s / sums.w;
    const double parent = sums.s * sums.s / sums.w;
    if (p.depth >= options.max_depth || p.end - p.begin < std::max(2, options.min_samples) || sums.q - parent <= 1e-12 * sums.q)
      continue;  // a leaf: deep enough, too few rows, or every label equal

    if (tries < d) draw_features(candidates, tries, d, rng);
    const Split best = best_split(g, p, candidates, tries, sums, parent);
    if (best.feature < 0 || best.score - parent <= 1e-12 * sums.q) continue;

    const double threshold = split_threshold(g, best);
    partition_segments(g, p, best, d, goes_left, scratch);
    const int left_rows = best.last_left - p.begin + 1;
    const int left = static_cast<int>(tree.size());
    tree.resize(tree.size() + 2);
    Node& n = tree[static_cast<std::size_t>(p.node)];
    n.feature = best.feature;
    n.threshold = threshold;
    n.left = left;
    n.right = left + 1;
    stack.push_back({left + 1, p.begin + left_rows, p.end, p.depth + 1});
    stack.push_back({left, p.begin, p.begin + left_rows, p.depth + 1});
  }
  return tree;
}

Matrix to_matrix(const std::vector<Tree>& trees) {
  std::size_t total = 0;
  for (const auto& t : trees) total += t.size();
  Matrix m(static_cast<Eigen::Index>(total), 5);
  Eigen::Index i = 0;
  for (const auto& t : trees)
    for (const Node& n : t) m.row(i++) << n.feature, n.threshold, n.left, n.right, n.value;
  return m;
}

std::vector<Tree> from_matrix(const Matrix& nodes, std::span<const double> sizes, std::size_t inputs, const std::string& who) {
  // `where()` names the value ("node 12", "tree 3's size"), built only for the message.
  auto integer = [&](double v, double lo, double hi, const auto& where) {
    if (!(v >= lo && v <= hi && v == std::floor(v)))
      throw InputError(who + ": model payload " + where() + " holds " + std::to_string(v) +
                       " where an integer in [" + std::to_string(static_cast<long long>(lo)) + ", " +
                       std::to_string(static_cast<long long>(hi)) + "] belongs");
    return static_cast<int>(v);
  };
  std::vector<Tree> trees;
  Eigen::Index at = 0;
  for (const double size_value : sizes) {
    const int size = integer(size_value, 1, static_cast<double>(nodes.rows() - at),
                             [&] { return "tree " + std::to_string(trees.size()) + "'s size"; });
    Tree t(static_cast<std::size_t>(size));
    for (int i = 0; i < size; ++i, ++at) {
      Node& n = t[static_cast<std::size_t>(i)];
      const auto node = [&] { return "node " + std::to_string(at); };
      n.feature = integer(nodes(at, 0), -1, static_cast<double>(inputs) - 1, node);
      n.threshold = nodes(at, 1);
      n.value = nodes(at, 4);
      if (n.feature < 0) continue;
      n.left = integer(nodes(at, 2), i + 1, size - 1, node);  // children after the parent: no loops
      n.right = integer(nodes(at, 3), i + 1, size - 1, node);
    }
    trees.push_back(std::move(t));
  }
  if (at != nodes.rows())
    throw InputError(who + ": model payload holds " + std::to_string(nodes.rows()) + " nodes, its trees " + std::to_string(at));
  return trees;
}

}  // namespace dicestack::forest
