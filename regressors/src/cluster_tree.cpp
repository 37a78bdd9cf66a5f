#include "cluster_tree.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <new>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

// The 8-lane helpers below pass vectors by value; they are internal and inlined, so no ABI is
// crossed and GCC's note that AVX changes it does not apply. Not popped: GCC reports the note
// at the end of the translation unit, which a unity build shares with the files after this one.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace dicestack {
namespace {

// Rounding slack of every bound: a box is skipped only when it lies farther than the k-th row
// found by more than float arithmetic over 64 terms can be off, so the search stays exact.
// Relative only: knn's rows are standardised, so no square underflows.
constexpr float kSlack = 1e-4f;

// 2-means steps that move each split plane after the median one.
constexpr int kRefinements = 10;

// Nodes and leaves waiting in the best-first queue; a child that finds it full is searched
// depth first at once.
constexpr std::size_t kQueue = 1024;

// Rows of a leaf measured in one call of the distance kernel.
constexpr std::size_t kBlock = 64;

// Distances in 8 lanes (GCC vector extensions: two SSE halves or one AVX register, the same
// arithmetic lane by lane); no fused multiply-add (the build passes -ffp-contract=off and the
// clones target AVX2 without FMA). So every CPU gets the same bits.
using V8 = float __attribute__((vector_size(32)));
using I8 = std::int32_t __attribute__((vector_size(32)));
constexpr std::size_t kLanes = 8;

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
inline float reduce(V8 a) { return ((a[0] + a[4]) + (a[2] + a[6])) + ((a[1] + a[5]) + (a[3] + a[7])); }

// One row against another: the columns in 8 lanes, each lane in column order, then the lanes.
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

#if defined(__x86_64__) && !defined(__clang__)
#define DICESTACK_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define DICESTACK_CLONES
#endif

// Distances from `q` to n consecutive rows (squared under l2).
DICESTACK_CLONES void rows_l2(const float* rows, std::size_t stride, std::size_t n, const float* q, float* out) {
  for (std::size_t m = 0; m < n; ++m) out[m] = sum_l2(rows + m * stride, q, stride);
}
DICESTACK_CLONES void rows_l1(const float* rows, std::size_t stride, std::size_t n, const float* q, float* out) {
  for (std::size_t m = 0; m < n; ++m) out[m] = sum_l1(rows + m * stride, q, stride);
}

// How far `q` lies outside each of eight boxes (squared under l2), stored column by column:
// the eight centres, then the eight half-widths. Outside a box by t = max(|q - c|, w) - w: never
// negative, and no comparison with zero. A lane without a box holds a half-width of -inf.
inline V8 outside(const float* boxes, float x) {
  const V8 w = load(boxes + kLanes), t = vabs(x - load(boxes));
  return (t > w ? t : w) - w;
}
DICESTACK_CLONES void boxes_l2(const float* boxes, const float* q, std::size_t cols, float* out) {
  V8 acc = {};
  for (std::size_t j = 0; j < cols; ++j, boxes += 2 * kLanes) {
    const V8 t = outside(boxes, q[j]);
    acc += t * t;
  }
  std::memcpy(out, &acc, sizeof acc);
}
DICESTACK_CLONES void boxes_l1(const float* boxes, const float* q, std::size_t cols, float* out) {
  V8 acc = {};
  for (std::size_t j = 0; j < cols; ++j, boxes += 2 * kLanes) acc += outside(boxes, q[j]);
  std::memcpy(out, &acc, sizeof acc);
}

template <class T>
T* allocate(std::size_t n) {
  const std::size_t bytes = std::max<std::size_t>(64, (n * sizeof(T) + 63) / 64 * 64);
  auto* p = static_cast<T*>(std::aligned_alloc(64, bytes));
  if (!p) throw std::bad_alloc();
  std::fill_n(p, bytes / sizeof(T), T{});
  return p;
}

}  // namespace

struct ClusterTree::Split {
  std::uint32_t begin, end;  // rows [begin, end) in order_
  std::uint32_t left = 0, right = 0;  // children (0: a leaf; the root is never a child)
};

// The k best so far, nearest first, in reported distances (squared under l2), equal distances
// by input row. limit(): a box farther than this (in reported distances) holds no better row.
class ClusterTree::Best {
 public:
  Best(std::size_t k, bool squared, const std::vector<std::size_t>& order, std::size_t* index, float* distance)
      : k_(k), order_(order), index_(index), distance_(distance) {
    // Metric distances b and a bound l: skip when l > b + kSlack (l + b), that is l (1 - kSlack)
    // > b (1 + kSlack); squared under l2.
    const float ratio = (1.0f + kSlack) / (1.0f - kSlack);
    stretch_ = squared ? ratio * ratio : ratio;
    // Near distance 0 a relative slack vanishes, while a box bound max(|q - c|, w) - w keeps an
    // absolute rounding error of about ulp(|q - c|) per column: below ~1000 standardised units,
    // under 6e-5, so under 2e-7 summed squared (3e-3 summed) over 64 columns.
    absolute_ = squared ? 1e-6f : 1e-2f;
  }

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
    if (n_ == k_) limit_ = distance_[k_ - 1] * stretch_ + absolute_;
  }
  float limit() const { return limit_; }
  std::size_t size() const { return n_; }

 private:
  bool before(float d, std::size_t i, std::size_t at) const {
    return d < distance_[at] || (d == distance_[at] && order_[i] < order_[index_[at]]);
  }

  std::size_t k_, n_ = 0;
  const std::vector<std::size_t>& order_;
  std::size_t* index_;
  float* distance_;
  float stretch_, absolute_;
  float limit_ = std::numeric_limits<float>::infinity();
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
  std::vector<Split> splits;
  std::vector<float> boxes, wide_boxes;
  split(rows, 0, static_cast<std::uint32_t>(order_.size()), splits, boxes);
  if (splits[0].left == 0) leaves_.push_back({splits[0].begin, splits[0].end});
  else widen(splits, boxes, 0, wide_boxes);
  boxes_.reset(allocate<float>(wide_boxes.size()));
  std::copy(wide_boxes.begin(), wide_boxes.end(), boxes_.get());
  // The rows of a leaf together: one cache-friendly run per leaf.
  rows_.reset(allocate<float>(order_.size() * stride_));
  for (std::size_t i = 0; i < order_.size(); ++i)
    std::copy_n(rows.row(static_cast<Eigen::Index>(order_[i])).data(), cols_, rows_.get() + i * stride_);
}

namespace {

// Row i of the rows a split divides: the input row order[i].
struct ClusterRows {
  const ClusterTree::Rows& rows;
  const std::vector<std::size_t>& order;
  const float* operator()(std::uint32_t i) const { return rows.row(static_cast<Eigen::Index>(order[i])).data(); }
};

// The mean of rows [begin, end), in double.
std::vector<double> cluster_mean(const ClusterRows& row, std::uint32_t begin, std::uint32_t end, std::size_t d) {
  std::vector<double> mean(d, 0.0);
  for (std::uint32_t i = begin; i < end; ++i)
    for (std::size_t j = 0; j < d; ++j) mean[j] += row(i)[j];
  for (double& m : mean) m /= static_cast<double>(end - begin);
  return mean;
}

// The bounding box of rows [begin, end): per column its least value in lo, its greatest in hi.
void cluster_box(const ClusterRows& row, std::uint32_t begin, std::uint32_t end, std::size_t d, float* lo, float* hi) {
  std::copy_n(row(begin), d, lo);
  std::copy_n(row(begin), d, hi);
  for (std::uint32_t i = begin + 1; i < end; ++i)
    for (std::size_t j = 0; j < d; ++j) lo[j] = std::min(lo[j], row(i)[j]), hi[j] = std::max(hi[j], row(i)[j]);
}

// The row of [begin, end) farthest from the mean (the first of equals; `begin` if all lie on
// it) and that metric distance (squared under l2).
std::pair<double, std::uint32_t> farthest_from_mean(const ClusterRows& row, std::uint32_t begin, std::uint32_t end,
                                                    const std::vector<double>& mean, bool l2) {
  double radius = 0.0;
  std::uint32_t farthest = begin;
  for (std::uint32_t i = begin; i < end; ++i) {
    double t = 0.0;
    for (std::size_t j = 0; j < mean.size(); ++j) {
      const double x = row(i)[j] - mean[j];
      t += l2 ? x * x : std::abs(x);
    }
    if (t > radius) radius = t, farthest = i;
  }
  return {radius, farthest};
}

// Row i's offset from the mean, projected on `dir`.
double cluster_along(const ClusterRows& row, std::uint32_t i, const std::vector<double>& mean, const std::vector<double>& dir) {
  double s = 0.0;
  for (std::size_t j = 0; j < mean.size(); ++j) s += (row(i)[j] - mean[j]) * dir[j];
  return s;
}

// The principal direction of rows [begin, end) by a few power iterations, from the farthest row's direction.
std::vector<double> principal_direction(const ClusterRows& row, std::uint32_t begin, std::uint32_t end,
                                        const std::vector<double>& mean, std::uint32_t farthest) {
  const std::size_t d = mean.size();
  std::vector<double> v(d), w(d);
  for (std::size_t j = 0; j < d; ++j) v[j] = row(farthest)[j] - mean[j];
  for (int it = 0; it < 3; ++it) {
    std::fill(w.begin(), w.end(), 0.0);
    for (std::uint32_t i = begin; i < end; ++i) {
      const double s = cluster_along(row, i, mean, v);
      for (std::size_t j = 0; j < d; ++j) w[j] += (row(i)[j] - mean[j]) * s;
    }
    double n = 0.0;
    for (const double x : w) n += x * x;
    if (!(n > 0.0)) break;
    n = std::sqrt(n);
    for (std::size_t j = 0; j < d; ++j) v[j] = w[j] / n;
  }
  return v;
}

// Which side of the median along `dir` each row of [begin, end) lies on (1: right). The median
// by rank (ties by position), so both sides hold rows even when many keys are equal.
std::vector<char> median_sides(const ClusterRows& row, std::uint32_t begin, std::uint32_t end, const std::vector<double>& mean,
                               const std::vector<double>& dir) {
  const std::uint32_t n = end - begin;
  std::vector<double> key(n);
  for (std::uint32_t i = 0; i < n; ++i) key[i] = cluster_along(row, begin + i, mean, dir);
  std::vector<std::uint32_t> rank(n);
  std::iota(rank.begin(), rank.end(), 0u);
  std::nth_element(rank.begin(), rank.begin() + n / 2, rank.end(),
                   [&](std::uint32_t x, std::uint32_t y) { return key[x] < key[y] || (key[x] == key[y] && x < y); });
  std::vector<char> on_right(n, 0);
  for (std::uint32_t i = n / 2; i < n; ++i) on_right[rank[i]] = 1;
  return on_right;
}

// Moves the plane between the sides of the rows from `begin` as 2-means would (the bisector of
// the two sides' means), which fits the clusters a trajectory set has better than the median.
void refine_sides(const ClusterRows& row, std::uint32_t begin, const std::vector<double>& mean, std::vector<char>& on_right) {
  const std::size_t d = mean.size();
  const auto n = static_cast<std::uint32_t>(on_right.size());
  std::vector<char> next(n);
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
    for (std::uint32_t i = 0; i < n; ++i) moved_right += (next[i] = cluster_along(row, begin + i, mean, u) > s) != 0;
    if (moved_right < least || n - moved_right < least) break;  // lopsided: keep the last balanced plane
    const bool same = next == on_right;
    on_right.swap(next);
    if (same) break;
  }
}

// Reorders order[begin, begin + n) stably into the left side's rows, then the right side's;
// returns how many lie on the left.
std::uint32_t partition_by_side(std::vector<std::size_t>& order, std::uint32_t begin, const std::vector<char>& on_right) {
  const auto n = static_cast<std::uint32_t>(on_right.size());
  std::vector<std::size_t> sides(order.begin() + begin, order.begin() + begin + n);
  std::uint32_t half = 0;
  for (std::uint32_t i = 0; i < n; ++i)
    if (!on_right[i]) order[begin + half++] = sides[i];
  for (std::uint32_t i = 0, r = half; i < n; ++i)
    if (on_right[i]) order[begin + r++] = sides[i];
  return half;
}

}  // namespace

std::uint32_t ClusterTree::split(Rows& rows, std::uint32_t begin, std::uint32_t end, std::vector<Split>& splits,
                                 std::vector<float>& boxes) {
  const std::size_t d = cols_;
  const ClusterRows row{rows, order_};
  const std::vector<double> mean = cluster_mean(row, begin, end, d);

  const auto id = static_cast<std::uint32_t>(splits.size());
  splits.push_back({begin, end});
  boxes.resize(boxes.size() + 2 * d);
  float* lo = boxes.data() + 2 * static_cast<std::size_t>(id) * d;
  cluster_box(row, begin, end, d, lo, lo + d);
  const auto [radius, farthest] = farthest_from_mean(row, begin, end, mean, metric_ == Metric::l2);
  if (end - begin <= leaf_size_ || radius == 0.0) return id;

  const std::vector<double> direction = principal_direction(row, begin, end, mean, farthest);
  // Start from the median along it, then move the plane as 2-means would.
  std::vector<char> on_right = median_sides(row, begin, end, mean, direction);
  refine_sides(row, begin, mean, on_right);
  const std::uint32_t half = partition_by_side(order_, begin, on_right);
  const std::uint32_t left = split(rows, begin, begin + half, splits, boxes);
  const std::uint32_t right = split(rows, begin + half, end, splits, boxes);
  splits[id].left = left;
  splits[id].right = right;
  return id;
}

std::uint32_t ClusterTree::widen(const std::vector<Split>& splits, const std::vector<float>& boxes, std::uint32_t top,
                                 std::vector<float>& wide_boxes) {
  // The children: the top split's, then the largest inner split among them replaced by its two,
  // until there are eight (three levels of a balanced tree). Kept in row order.
  std::vector<std::uint32_t> members = {splits[top].left, splits[top].right};
  while (members.size() < kFan) {
    std::size_t largest = members.size();
    for (std::size_t m = 0; m < members.size(); ++m) {
      const Split& s = splits[members[m]];
      if (s.left != 0 && (largest == members.size() || s.end - s.begin > splits[members[largest]].end - splits[members[largest]].begin))
        largest = m;
    }
    if (largest == members.size()) break;
    const Split& s = splits[members[largest]];
    members[largest] = s.right;
    members.insert(members.begin() + static_cast<std::ptrdiff_t>(largest), s.left);
  }
  const auto id = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back({});
  nodes_[id].children = static_cast<std::uint32_t>(members.size());
  const std::size_t at = wide_boxes.size(), d = cols_;
  wide_boxes.resize(at + 2 * kLanes * d);
  for (std::size_t j = 0; j < d; ++j)
    for (std::size_t lane = 0; lane < kLanes; ++lane) {
      wide_boxes[at + 2 * kLanes * j + lane] = 0.0f;
      wide_boxes[at + 2 * kLanes * j + kLanes + lane] = -std::numeric_limits<float>::infinity();
    }
  for (std::size_t m = 0; m < members.size(); ++m) {
    const Split& s = splits[members[m]];
    const float* lo = boxes.data() + 2 * static_cast<std::size_t>(members[m]) * d;
    for (std::size_t j = 0; j < d; ++j) {
      // The centre, and a half-width rounded up until the box holds [lo, hi] in float arithmetic.
      const float c = static_cast<float>((static_cast<double>(lo[j]) + static_cast<double>(lo[d + j])) / 2.0);
      float w = static_cast<float>(std::max(static_cast<double>(lo[d + j]) - c, c - static_cast<double>(lo[j])));
      while (c - w > lo[j] || c + w < lo[d + j]) w = std::nextafter(w, std::numeric_limits<float>::infinity());
      wide_boxes[at + 2 * kLanes * j + m] = c;
      wide_boxes[at + 2 * kLanes * j + kLanes + m] = w;
    }
    std::uint32_t child;
    if (s.left == 0) {
      child = kLeaf | static_cast<std::uint32_t>(leaves_.size());
      leaves_.push_back({s.begin, s.end});
    } else {
      child = widen(splits, boxes, members[m], wide_boxes);
    }
    nodes_[id].child[m] = child;
  }
  return id;
}

void ClusterTree::bounds(std::uint32_t node, const float* query, float* out) const {
  const float* boxes = boxes_.get() + static_cast<std::size_t>(node) * 2 * kLanes * cols_;
  if (metric_ == Metric::l2) boxes_l2(boxes, query, cols_, out);
  else boxes_l1(boxes, query, cols_, out);
}

void ClusterTree::scan(const Leaf& leaf, const float* query, Best& best) const {
  float found[kBlock];
  for (std::uint32_t from = leaf.begin; from < leaf.end; from += kBlock) {
    const std::size_t n = std::min<std::size_t>(leaf.end - from, kBlock);
    if (metric_ == Metric::l2) rows_l2(row(from), stride_, n, query, found);
    else rows_l1(row(from), stride_, n, query, found);
    for (std::size_t m = 0; m < n; ++m) best.offer(found[m], from + m);
  }
}

void ClusterTree::visit(std::uint32_t child, float bound, const float* query, Best& best) const {
  if (bound > best.limit()) return;
  if (child & kLeaf) return scan(leaves_[child & ~kLeaf], query, best);
  const Node& node = nodes_[child];
  float b[kFan];
  bounds(child, query, b);
  std::uint32_t by_bound[kFan];  // nearest first (insertion: at most eight)
  for (std::uint32_t m = 0; m < node.children; ++m) {
    std::uint32_t at = m;
    for (; at > 0 && b[by_bound[at - 1]] > b[m]; --at) by_bound[at] = by_bound[at - 1];
    by_bound[at] = m;
  }
  for (std::uint32_t m = 0; m < node.children; ++m) visit(node.child[by_bound[m]], b[by_bound[m]], query, best);
}

std::size_t ClusterTree::search(const float* query, std::size_t k, std::size_t* index, float* distance_out) const {
  k = std::min(k, order_.size());
  if (k == 0) return 0;
  alignas(64) float q[kMaxCols] = {};
  std::copy_n(query, cols_, q);
  Best best(k, metric_ == Metric::l2, order_, index, distance_out);
  if (nodes_.empty()) {
    scan(leaves_[0], q, best);
    return best.size();
  }
  // Best first: the node or leaf whose box lies nearest is taken next, down along the nearest
  // child with the others queued; the search ends when the nearest queued box lies farther
  // than the k-th row found. A queued entry is its bound's bits (bounds are >= 0, so their
  // bits order as the bounds do) above the child's reference: one integer comparison.
  std::uint64_t queue[kQueue];
  std::size_t waiting = 0;
  const auto entry = [](float bound, std::uint32_t child) {
    std::uint32_t bits;
    std::memcpy(&bits, &bound, sizeof bits);
    return std::uint64_t{bits} << 32 | child;
  };
  const auto later = std::greater<std::uint64_t>();  // a min-heap
  std::uint32_t child = 0;
  for (;;) {
    if (child & kLeaf) {
      scan(leaves_[child & ~kLeaf], q, best);
    } else {
      const Node& node = nodes_[child];
      float b[kFan];
      bounds(child, q, b);
      std::uint32_t nearest = kFan;
      for (std::uint32_t m = 0; m < node.children; ++m) {
        if (b[m] > best.limit()) continue;
        std::uint32_t queued = m;
        if (nearest == kFan) {
          nearest = m;
          continue;
        }
        if (b[m] < b[nearest]) std::swap(queued, nearest);
        if (waiting == kQueue) {
          visit(node.child[queued], b[queued], q, best);
        } else {
          queue[waiting++] = entry(b[queued], node.child[queued]);
          std::push_heap(queue, queue + waiting, later);
        }
      }
      if (nearest != kFan) {
        child = node.child[nearest];
        continue;
      }
    }
    if (waiting == 0) break;
    std::pop_heap(queue, queue + waiting, later);
    const std::uint64_t next = queue[--waiting];
    const auto bits = static_cast<std::uint32_t>(next >> 32);
    float bound;
    std::memcpy(&bound, &bits, sizeof bound);
    if (bound > best.limit()) break;
    child = static_cast<std::uint32_t>(next);
  }
  return best.size();
}

}  // namespace dicestack

#undef DICESTACK_CLONES
