#pragma once
// Private to regressors/: xgboost's trees read from its JSON model and evaluated by us. One row
// through 300 trees costs xgboost's C API 60-100 us of call overhead (DMatrix-free inplace
// prediction still parses an array interface and dispatches per call); walking flat arrays
// costs a few. Reading the JSON ourselves also validates every index before anything walks
// it, so an edited payload is refused with the tree and node named instead of crashing
// xgboost's predictor.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace dicestack::detail {

/// A gradient-boosted forest of numerical regression trees, as xgboost 1.7 saves it
/// ("gbtree", reg:squarederror, one output per tree).
class XgbForest {
 public:
  /// Parses and validates a JSON model for `inputs` features and `outputs` targets. Throws
  /// InputError ("gbt: tree 3 node 7: ...") for anything a walk could trip on: array sizes,
  /// child indices, cycles, split features, categorical splits, tree targets, non-finite values.
  static XgbForest parse(std::string_view json, std::size_t inputs, std::size_t outputs);

  /// Predicts one row as xgboost does: base score plus the leaf values of each output's trees,
  /// summed in float in tree order (x < threshold goes left; a NaN follows the default side).
  void predict(std::span<const double> x, std::span<double> y) const;

  std::size_t trees() const { return roots_.size(); }

 private:
  static constexpr std::size_t kMaxInputs = 256, kMaxOutputs = 64;  // stack rows on the hot path
  static constexpr std::uint32_t kDefaultLeft = 1u << 31;  // in Node::feature: a NaN goes left
  struct Node {
    std::int32_t left = -1;     ///< index of the left child (the right one follows it); -1 for a leaf
    std::uint32_t feature = 0;  ///< split feature, | kDefaultLeft
    float value = 0.0f;         ///< split threshold, or the leaf value
  };
  std::vector<Node> nodes_;
  std::vector<std::uint32_t> roots_, targets_;
  float base_score_ = 0.0f;
  std::size_t outputs_ = 0;
};

}  // namespace dicestack::detail
