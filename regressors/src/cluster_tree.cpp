#include "cluster_tree.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <new>
#include <numeric>
#include <stdexcept>
#include <string>

// The 8-lane helpers below pass vectors by value; they are internal and inlined, so no ABI is
// crossed and GCC's note that AVX changes it does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace dicestack {
namespace {

// Rounding slack of every bound: a node or row is skipped only when it is farther than the
// k-th found by more than float arithmetic over 64 terms can be off, so the search stays exact.
// Relative only: knn's rows are standardised, so no square underflows.
constexpr float kSlack = 1e-4f;

// 2-means steps that move each split plane after the median one.
constexpr int kRefinements = 10;

// Nodes waiting in the best-first queue; a node that finds it full is searched depth first.
constexpr std::size_t kQueue = 512;

// Rows of a leaf measured in one call of the distance kernel.
constexpr std::size_t kBlock = 64;

bool beyond(float lower_bound, float bound, float scale) { return lower_bound > bound + kSlack * (scale + bound); }

// Distances in 8 lanes (GCC vector extensions: two SSE halves or one AVX register, the same
// arithmetic lane by lane), summed lane by lane over the columns in order, then the lanes
// pairwise in one fixed order; no fused multiply-add (the build passes -ffp-contract=off and
// the clones target AVX2 without FMA). So every CPU gets the same bits.
using V8 = float __attribute__((vector_size(32)));
using I8 = std::int32_t __attribute__((vector_size(32)));
using H8 = std::uint16_t __attribute__((vector_size(16)));
constexpr std::size_t kLanes = 8;

// Boxes are stored as bfloat16 (a float's upper half), rounded outwards: half the memory the
// search reads, and a box that only grows keeps every bound a bound.
std::uint16_t bf16_down(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  auto h = static_cast<std::uint16_t>(bits >> 16);
  if ((bits & 0xffffu) != 0 && (bits >> 31) != 0) ++h;  // a negative value truncated towards zero: one step away
  return h;
}
std::uint16_t bf16_up(float x) {
  std::uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  auto h = static_cast<std::uint16_t>(bits >> 16);
  if ((bits & 0xffffu) != 0 && (bits >> 31) == 0) ++h;
  return h;
}

inline V8 load(const float* p) {
  V8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline V8 vabs(V8 v) {
  I8 bits;
  std::memcpy(&bits, &v, sizeof v);
  bits &= 0x7fffffff;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}
inline V8 load_bf16(const std::uint16_t* p) {
  H8 h;
  std::memcpy(&h, p, sizeof h);
  const I8 bits = __builtin_convertvector(h, I8) << 16;
  V8 v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}
inline float reduce(V8 a) { return ((a[0] + a[4]) + (a[2] + a[6])) + ((a[1] + a[5]) + (a[3] + a[7])); }

inline float sum_l2(const float* a, const float* b, std::size_t stride) {
  V8 acc = {};
  for (std::size_t j = 0; j < stride; j += kLanes) {
    const V8 t = load(a + j) - load(b + j);
    acc += t * t;
  }
  return reduce(acc);
}
inline float sum_l1(const float* a, const float* b, std::size_t stride) {
  V8 acc = {};
  for (std::size_t j = 0; j < stride; j += kLanes) acc += vabs(load(a + j) - load(b + j));
  return reduce(acc);
}

#define DICESTACK_CLONES __attribute__((target_clones("avx2", "default")))

// Distances from `q` to the picked rows (squared under l2).
DICESTACK_CLONES void rows_l2(const float* rows, std::size_t stride, const std::uint32_t* pick, std::size_t n, const float* q,
                              float* out) {
  for (std::size_t m = 0; m < n; ++m) out[m] = sum_l2(rows + pick[m] * stride, q, stride);
}
DICESTACK_CLONES void rows_l1(const float* rows, std::size_t stride, const std::uint32_t* pick, std::size_t n, const float* q,
                              float* out) {
  for (std::size_t m = 0; m < n; ++m) out[m] = sum_l1(rows + pick[m] * stride, q, stride);
}

// How far `q` lies outside each of two boxes, stored as least then greatest values of each
// column, one box after the other (squared under l2).
DICESTACK_CLONES void boxes_l2(const std::uint16_t* boxes, const float* q, std::size_t stride, float* out) {
  for (int b = 0; b < 2; ++b, boxes += 2 * stride) {
    V8 acc = {};
    const V8 zero = {};
    for (std::size_t j = 0; j < stride; j += kLanes) {
      const V8 x = load(q + j), below = load_bf16(boxes + j) - x, above = x - load_bf16(boxes + stride + j);
      V8 t = below > above ? below : above;
      t = t > zero ? t : zero;
      acc += t * t;
    }
    out[b] = reduce(acc);
  }
}
DICESTACK_CLONES void boxes_l1(const std::uint16_t* boxes, const float* q, std::size_t stride, float* out) {
  for (int b = 0; b < 2; ++b, boxes += 2 * stride) {
    V8 acc = {};
    const V8 zero = {};
    for (std::size_t j = 0; j < stride; j += kLanes) {
      const V8 x = load(q + j), below = load_bf16(boxes + j) - x, above = x - load_bf16(boxes + stride + j);
      V8 t = below > above ? below : above;
      acc += t > zero ? t : zero;
    }
    out[b] = reduce(acc);
  }
}

DICESTACK_CLONES float pair_l2(const float* a, const float* b, std::size_t stride) { return sum_l2(a, b, stride); }
DICESTACK_CLONES float pair_l1(const float* a, const float* b, std::size_t stride) { return sum_l1(a, b, stride); }

template <class T>
T* allocate(std::size_t n) {
  const std::size_t bytes = std::max<std::size_t>(64, (n * sizeof(T) + 63) / 64 * 64);
  auto* p = static_cast<T*>(std::aligned_alloc(64, bytes));
  if (!p) throw std::bad_alloc();
  std::fill_n(p, bytes / sizeof(T), T{});
  return p;
}

void prefetch(const void* p, std::size_t bytes) {
  for (std::size_t at = 0; at < bytes; at += 64) __builtin_prefetch(static_cast<const char*>(p) + at);
}

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
    : cols_(static_cast<std::size_t>(rows.cols())),
      stride_((cols_ + kLanes - 1) / kLanes * kLanes),
      metric_(metric),
      leaf_size_(std::max<std::size_t>(leaf_size, 1)) {
  if (cols_ > kMaxCols)
    throw std::invalid_argument("ClusterTree: " + std::to_string(cols_) + " columns; at most " + std::to_string(kMaxCols));
  order_.resize(static_cast<std::size_t>(rows.rows()));
  std::iota(order_.begin(), order_.end(), std::size_t{0});
  if (order_.empty()) return;
  to_centre_.resize(order_.size());
  std::vector<float> centres, boxes;
  build(rows, 0, static_cast<std::uint32_t>(order_.size()), centres, boxes);
  centres_.reset(allocate<float>(centres.size()));
  std::copy(centres.begin(), centres.end(), centres_.get());
  // Each inner node holds its children's boxes side by side: one run of memory per step down.
  boxes_.reset(allocate<std::uint16_t>(nodes_.size() * 4 * stride_));
  for (std::size_t id = 0; id < nodes_.size(); ++id) {
    if (nodes_[id].left == 0) continue;
    std::uint16_t* out = boxes_.get() + id * 4 * stride_;
    for (const std::uint32_t child : {nodes_[id].left, nodes_[id].right}) {
      const float* lo = boxes.data() + 2 * static_cast<std::size_t>(child) * stride_;
      for (std::size_t j = 0; j < stride_; ++j) out[j] = bf16_down(lo[j]), out[stride_ + j] = bf16_up(lo[stride_ + j]);
      out += 2 * stride_;
    }
  }
  // The rows of a leaf together: one cache-friendly run per leaf.
  rows_.reset(allocate<float>(order_.size() * stride_));
  for (std::size_t i = 0; i < order_.size(); ++i)
    std::copy_n(rows.row(static_cast<Eigen::Index>(order_[i])).data(), cols_, rows_.get() + i * stride_);
}

float ClusterTree::row_distance(const float* a, const float* b) const {
  alignas(64) float pa[kMaxCols] = {}, pb[kMaxCols] = {};
  std::copy_n(a, cols_, pa);
  std::copy_n(b, cols_, pb);
  return metric_ == Metric::l2 ? pair_l2(pa, pb, stride_) : pair_l1(pa, pb, stride_);
}

float ClusterTree::distance(const float* a, const float* b) const {
  return metric_ == Metric::l2 ? std::sqrt(pair_l2(a, b, stride_)) : pair_l1(a, b, stride_);
}

std::uint32_t ClusterTree::build(Rows& rows, std::uint32_t begin, std::uint32_t end, std::vector<float>& centres,
                                 std::vector<float>& boxes) {
  const std::size_t d = cols_;
  const auto row = [&](std::uint32_t i) { return rows.row(static_cast<Eigen::Index>(order_[i])).data(); };
  std::vector<double> mean(d, 0.0);
  for (std::uint32_t i = begin; i < end; ++i)
    for (std::size_t j = 0; j < d; ++j) mean[j] += row(i)[j];
  for (double& m : mean) m /= static_cast<double>(end - begin);

  const auto id = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({begin, end});
  centres.resize(centres.size() + stride_, 0.0f);
  boxes.resize(boxes.size() + 2 * stride_, 0.0f);
  float* c = centres.data() + static_cast<std::size_t>(id) * stride_;
  for (std::size_t j = 0; j < d; ++j) c[j] = static_cast<float>(mean[j]);
  float* lo = boxes.data() + 2 * static_cast<std::size_t>(id) * stride_;
  float* hi = lo + stride_;
  std::copy_n(row(begin), d, lo);
  std::copy_n(row(begin), d, hi);
  for (std::uint32_t i = begin + 1; i < end; ++i)
    for (std::size_t j = 0; j < d; ++j) lo[j] = std::min(lo[j], row(i)[j]), hi[j] = std::max(hi[j], row(i)[j]);
  float radius = 0.0f;
  std::uint32_t farthest = begin;
  alignas(64) float padded[kMaxCols] = {};
  for (std::uint32_t i = begin; i < end; ++i) {
    std::copy_n(row(i), d, padded);
    const float t = distance(padded, c);
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
  const std::uint32_t left = build(rows, begin, begin + half, centres, boxes);
  const std::uint32_t right = build(rows, begin + half, end, centres, boxes);
  nodes_[id].left = left;
  nodes_[id].right = right;
  return id;
}

void ClusterTree::children_bounds(std::uint32_t node, const float* query, float* bounds) const {
  const std::uint16_t* boxes = children_boxes(node);
  if (metric_ == Metric::l1) return boxes_l1(boxes, query, stride_, bounds);
  boxes_l2(boxes, query, stride_, bounds);
  bounds[0] = std::sqrt(bounds[0]);
  bounds[1] = std::sqrt(bounds[1]);
}

void ClusterTree::scan_leaf(std::uint32_t id, const float* query, Best& best) const {
  const Node& node = nodes_[id];
  prefetch(row(node.begin), (node.end - node.begin) * stride_ * sizeof(float));
  const float to_centre = distance(query, centre(id));
  if (beyond(to_centre - node.radius, best.bound(), to_centre + node.radius)) return;
  std::uint32_t pick[kBlock];
  float found[kBlock];
  for (std::uint32_t from = node.begin; from < node.end; from += kBlock) {
    const std::uint32_t to = std::min<std::uint32_t>(node.end, from + kBlock);
    const float bound = best.bound();  // stale within the block: it only skips fewer rows
    std::size_t n = 0;
    for (std::uint32_t i = from; i < to; ++i) {
      const float t = to_centre_[i];
      if (!beyond(std::abs(to_centre - t), bound, to_centre + t)) pick[n++] = i;
    }
    if (metric_ == Metric::l2) rows_l2(rows_.get(), stride_, pick, n, query, found);
    else rows_l1(rows_.get(), stride_, pick, n, query, found);
    for (std::size_t m = 0; m < n; ++m) best.offer(found[m], pick[m]);
  }
}

void ClusterTree::visit(std::uint32_t id, float lower_bound, const float* query, Best& best) const {
  if (beyond(lower_bound, best.bound(), lower_bound)) return;
  const Node& node = nodes_[id];
  if (node.left == 0) return scan_leaf(id, query, best);
  float bounds[2];
  children_bounds(id, query, bounds);
  const float l = bounds[0], r = bounds[1];
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
  alignas(64) float q[kMaxCols] = {};
  std::copy_n(query, cols_, q);
  Best best(k, metric_ == Metric::l2, order_, index, distance_out);
  // Best first: the node whose box lies nearest is searched next, down to a leaf along the
  // nearer child, the farther one queued; the search ends when the nearest queued box lies
  // beyond the k-th row found.
  struct Pending {
    float bound;
    std::uint32_t node;
    bool operator<(const Pending& o) const { return bound > o.bound; }  // a min-heap
  };
  Pending queue[kQueue];
  std::size_t queued = 0;
  queue[queued++] = {0.0f, 0};
  while (queued > 0) {
    std::pop_heap(queue, queue + queued);
    auto [lower_bound, id] = queue[--queued];
    if (beyond(lower_bound, best.bound(), lower_bound)) break;
    while (nodes_[id].left != 0) {
      const Node& node = nodes_[id];
      prefetch(children_boxes(node.left), 4 * stride_ * sizeof(std::uint16_t));
      prefetch(children_boxes(node.right), 4 * stride_ * sizeof(std::uint16_t));
      float bounds[2];
      children_bounds(id, q, bounds);
      float l = bounds[0], r = bounds[1];
      std::uint32_t near = node.left, far = node.right;
      if (r < l) std::swap(near, far), std::swap(l, r);
      if (!beyond(r, best.bound(), r)) {
        if (queued < kQueue) {
          queue[queued++] = {r, far};
          std::push_heap(queue, queue + queued);
        } else {
          visit(far, r, q, best);
        }
      }
      if (beyond(l, best.bound(), l)) break;
      id = near;
    }
    if (nodes_[id].left == 0) scan_leaf(id, q, best);
  }
  return best.size();
}

}  // namespace dicestack
