#include "cluster_tree.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace dicestack {
namespace {

using Vec = Eigen::Map<const Eigen::VectorXf>;

// Rounding slack of every bound: a node or row is skipped only when it is farther than the
// k-th found by more than float arithmetic over 64 terms can be off, so the search stays exact.
// Relative only: knn's rows are standardised, so no square underflows.
constexpr float kSlack = 1e-4f;

// 2-means steps that move each split plane after the median one.
constexpr int kRefinements = 10;

bool beyond(float lower_bound, float bound, float scale) { return lower_bound > bound + kSlack * (scale + bound); }

}  // namespace

// The k best so far, nearest first, in reported distances (squared under l2), equal distances
// by input row; bound() is the k-th's metric distance, what a node's box and a leaf's ball are compared with.
class ClusterTree::Best {
 public:
  Best(std::size_t k, bool squared, const std::vector<std::size_t>& order, std::size_t* index, float* distance)
      : k_(k), squared_(squared), order_(order), index_(index), distance_(distance) {}

  void offer(float d, std::size_t i) {
    if (n_ == k_ && !before(d, i, k_ - 1)) return;
    std::size_t at = std::min(n_, k_ - 1);
    while (at > 0 && before(d, i, at - 1)) {
      distance_[at] = distance_[at - 1];
      index_[at] = index_[at - 1];
      --at;
    }
    distance_[at] = d;
    index_[at] = i;
    if (n_ < k_) ++n_;
    if (n_ == k_) bound_ = squared_ ? std::sqrt(distance_[k_ - 1]) : distance_[k_ - 1];
  }
  float bound() const { return bound_; }
  std::size_t size() const { return n_; }

 private:
  bool before(float d, std::size_t i, std::size_t at) const {
    return d < distance_[at] || (d == distance_[at] && order_[i] < order_[index_[at]]);
  }

  std::size_t k_, n_ = 0;
  bool squared_;
  const std::vector<std::size_t>& order_;
  std::size_t* index_;
  float* distance_;
  float bound_ = std::numeric_limits<float>::infinity();
};

ClusterTree::ClusterTree(Rows rows, Metric metric, std::size_t leaf_size)
    : rows_(std::move(rows)), metric_(metric), leaf_size_(std::max<std::size_t>(leaf_size, 1)) {
  order_.resize(static_cast<std::size_t>(rows_.rows()));
  std::iota(order_.begin(), order_.end(), std::size_t{0});
  if (order_.empty()) return;
  to_centre_.resize(order_.size());
  build(0, static_cast<std::uint32_t>(order_.size()));
  Rows sorted(rows_.rows(), rows_.cols());  // the rows of a leaf together: one cache-friendly run per leaf
  for (std::size_t i = 0; i < order_.size(); ++i)
    sorted.row(static_cast<Eigen::Index>(i)) = rows_.row(static_cast<Eigen::Index>(order_[i]));
  rows_ = std::move(sorted);
}

float ClusterTree::distance(const float* a, const float* b) const {
  const auto d = static_cast<Eigen::Index>(cols());
  const auto diff = Vec(a, d) - Vec(b, d);
  return metric_ == Metric::l2 ? std::sqrt(diff.squaredNorm()) : diff.cwiseAbs().sum();
}

std::uint32_t ClusterTree::build(std::uint32_t begin, std::uint32_t end) {
  const std::size_t d = cols();
  const auto row = [&](std::uint32_t i) { return rows_.row(static_cast<Eigen::Index>(order_[i])).data(); };
  std::vector<double> mean(d, 0.0);
  for (std::uint32_t i = begin; i < end; ++i)
    for (std::size_t j = 0; j < d; ++j) mean[j] += row(i)[j];
  for (double& m : mean) m /= static_cast<double>(end - begin);

  const auto id = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({begin, end});
  for (const double m : mean) centres_.push_back(static_cast<float>(m));
  boxes_.resize(centres_.size() * 2);
  float* lo = boxes_.data() + 2 * static_cast<std::size_t>(id) * d;
  float* hi = lo + d;
  std::copy_n(row(begin), d, lo);
  std::copy_n(row(begin), d, hi);
  for (std::uint32_t i = begin + 1; i < end; ++i)
    for (std::size_t j = 0; j < d; ++j) lo[j] = std::min(lo[j], row(i)[j]), hi[j] = std::max(hi[j], row(i)[j]);
  const float* c = centre(id);
  float radius = 0.0f;
  std::uint32_t farthest = begin;
  for (std::uint32_t i = begin; i < end; ++i) {
    const float t = distance(row(i), c);
    to_centre_[i] = t;  // a leaf's rows keep their positions: this is final once the node is a leaf
    if (t > radius) radius = t, farthest = i;
  }
  nodes_[id].radius = radius;
  if (end - begin <= leaf_size_ || radius == 0.0f) return id;

  // The principal direction by a few power iterations, from the farthest row's direction.
  std::vector<double> v(d), w(d);
  for (std::size_t j = 0; j < d; ++j) v[j] = row(farthest)[j] - mean[j];
  const auto along = [&](std::uint32_t i, const std::vector<double>& dir) {
    double s = 0.0;
    for (std::size_t j = 0; j < d; ++j) s += (row(i)[j] - mean[j]) * dir[j];
    return s;
  };
  for (int it = 0; it < 3; ++it) {
    std::fill(w.begin(), w.end(), 0.0);
    for (std::uint32_t i = begin; i < end; ++i) {
      const double s = along(i, v);
      for (std::size_t j = 0; j < d; ++j) w[j] += (row(i)[j] - mean[j]) * s;
    }
    double n = 0.0;
    for (const double x : w) n += x * x;
    if (!(n > 0.0)) break;
    n = std::sqrt(n);
    for (std::size_t j = 0; j < d; ++j) v[j] = w[j] / n;
  }
  // Start from the median along it, then move the plane as 2-means would (the bisector of the
  // two sides' means), which fits the clusters a trajectory set has better than the median.
  const std::uint32_t n = end - begin;
  std::vector<double> key(n);
  for (std::uint32_t i = 0; i < n; ++i) key[i] = along(begin + i, v);
  // The median by rank (ties by position), so both sides hold rows even when many keys are equal.
  std::vector<std::uint32_t> rank(n);
  std::iota(rank.begin(), rank.end(), 0u);
  std::nth_element(rank.begin(), rank.begin() + n / 2, rank.end(),
                   [&](std::uint32_t x, std::uint32_t y) { return key[x] < key[y] || (key[x] == key[y] && x < y); });
  std::vector<char> on_right(n, 0), next(n);
  for (std::uint32_t i = n / 2; i < n; ++i) on_right[rank[i]] = 1;
  const std::uint32_t least = std::max<std::uint32_t>(1, n / 8);
  std::vector<double> a(d), b(d), u(d);
  for (int it = 0; it < kRefinements; ++it) {
    std::fill(a.begin(), a.end(), 0.0);
    std::fill(b.begin(), b.end(), 0.0);
    std::uint32_t nb = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      auto& side = on_right[i] ? b : a;
      nb += on_right[i] != 0;
      for (std::size_t j = 0; j < d; ++j) side[j] += row(begin + i)[j] - mean[j];
    }
    if (nb == 0 || nb == n) break;
    double norm = 0.0, aa = 0.0, bb = 0.0;
    for (std::size_t j = 0; j < d; ++j) {
      a[j] /= static_cast<double>(n - nb);
      b[j] /= static_cast<double>(nb);
      u[j] = b[j] - a[j];
      norm += u[j] * u[j];
      aa += a[j] * a[j];
      bb += b[j] * b[j];
    }
    if (!(norm > 0.0)) break;
    norm = std::sqrt(norm);
    for (double& x : u) x /= norm;
    const double s = (bb - aa) / (2.0 * norm);
    std::uint32_t moved_right = 0;
    for (std::uint32_t i = 0; i < n; ++i) moved_right += (next[i] = along(begin + i, u) > s) != 0;
    if (moved_right < least || n - moved_right < least) break;  // lopsided: keep the last balanced plane
    const bool same = next == on_right;
    on_right.swap(next);
    if (same) break;
  }
  std::vector<std::size_t> sides(order_.begin() + begin, order_.begin() + end);
  std::uint32_t half = 0;
  for (std::uint32_t i = 0; i < n; ++i)
    if (!on_right[i]) order_[begin + half++] = sides[i];
  for (std::uint32_t i = 0, r = half; i < n; ++i)
    if (on_right[i]) order_[begin + r++] = sides[i];
  const std::uint32_t left = build(begin, begin + half);
  const std::uint32_t right = build(begin + half, end);
  nodes_[id].left = left;
  nodes_[id].right = right;
  return id;
}

float ClusterTree::box_distance(std::uint32_t node, const float* query) const {
  const auto d = static_cast<Eigen::Index>(cols());
  const auto q = Vec(query, d).array();
  const auto lo = Vec(box(node), d).array(), hi = Vec(box(node) + d, d).array();
  const auto outside = (lo - q).max(q - hi).max(0.0f);  // per column: how far outside the box
  return metric_ == Metric::l2 ? std::sqrt(outside.square().sum()) : outside.sum();
}

void ClusterTree::visit(std::uint32_t id, float lower_bound, const float* query, Best& best) const {
  if (beyond(lower_bound, best.bound(), lower_bound)) return;
  const Node& node = nodes_[id];
  if (node.left == 0) {
    const float to_centre = distance(query, centre(id));
    if (beyond(to_centre - node.radius, best.bound(), to_centre + node.radius)) return;
    const auto d = static_cast<Eigen::Index>(cols());
    for (std::uint32_t i = node.begin; i < node.end; ++i) {
      const float t = to_centre_[i];
      if (beyond(std::abs(to_centre - t), best.bound(), to_centre + t)) continue;
      const auto diff = Vec(rows_.row(static_cast<Eigen::Index>(i)).data(), d) - Vec(query, d);
      best.offer(metric_ == Metric::l2 ? diff.squaredNorm() : diff.cwiseAbs().sum(), i);
    }
    return;
  }
  const float l = box_distance(node.left, query), r = box_distance(node.right, query);
  if (l <= r) {
    visit(node.left, l, query, best);
    visit(node.right, r, query, best);
  } else {
    visit(node.right, r, query, best);
    visit(node.left, l, query, best);
  }
}

std::size_t ClusterTree::search(const float* query, std::size_t k, std::size_t* index, float* distance_out) const {
  k = std::min(k, order_.size());
  if (k == 0) return 0;
  Best best(k, metric_ == Metric::l2, order_, index, distance_out);
  visit(0, box_distance(0, query), query, best);
  return best.size();
}

}  // namespace dicestack
