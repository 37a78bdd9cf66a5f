#include "xgb_forest.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/json_depth.hpp>

namespace dicestack::detail {
namespace {

// Floats parsed as floats (strtof), so thresholds and leaf values are bit-identical to xgboost's.
using FloatJson = nlohmann::basic_json<std::map, std::vector, std::string, bool, std::int64_t, std::uint64_t, float>;

[[noreturn]] void fail(const std::string& what) { throw InputError("gbt: " + what); }

// An integer from the payload: a float (1.5, 1e30) is refused, never converted.
std::int64_t integer(const FloatJson& v, const std::string& what) {
  if (!v.is_number_integer() || (v.is_number_unsigned() && v.get<std::uint64_t>() > (std::uint64_t{1} << 62)))
    fail(what + " is not an integer index, got " + v.dump().substr(0, 40));
  return v.get<std::int64_t>();
}

// A count xgboost stores as text ("3"): digits only, the whole string.
std::uint64_t count_text(const FloatJson& v, const std::string& what) {
  const std::string text = v.get<std::string>();
  std::uint64_t out = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    fail(what + " is not a count, got \"" + text.substr(0, 40) + "\"");
  return out;
}

// The payload as JSON, floats read as floats.
FloatJson parse_xgb_json(std::string_view text) {
  try {
    return parse_json_limited<FloatJson>(text, "gbt payload");
  } catch (const FloatJson::exception& e) {
    fail(std::string("the payload is not xgboost's JSON model: ") + e.what());
  } catch (const InputError& e) {
    fail(e.what());
  }
}

// Checks the learner's objective, target and feature counts, base score and booster, and that
// tree_info and num_trees agree with the trees present; returns the booster's model.
const FloatJson& read_xgb_model(const FloatJson& j, std::size_t inputs, std::size_t outputs, float& base_score) {
  const auto& learner = j.at("learner");
  if (learner.at("objective").at("name").get<std::string>() != "reg:squarederror")
    fail("the model's objective is not reg:squarederror");
  const auto& param = learner.at("learner_model_param");
  const auto targets = count_text(param.at("num_target"), "num_target");
  if (targets != outputs)
    fail("the model has " + std::to_string(targets) + " targets, the header says " + std::to_string(outputs));
  if (count_text(param.at("num_feature"), "num_feature") != inputs)
    fail("the model reads " + param.at("num_feature").get<std::string>() + " features, the header says " +
         std::to_string(inputs));
  base_score = std::stof(param.at("base_score").get<std::string>());
  if (!std::isfinite(base_score)) fail("base_score is not finite");
  const auto& booster = learner.at("gradient_booster");
  if (booster.at("name").get<std::string>() != "gbtree") fail("the booster is not gbtree");
  const auto& model = booster.at("model");
  const auto& trees = model.at("trees");
  const auto& info = model.at("tree_info");
  if (!trees.is_array() || !info.is_array() || trees.size() != info.size())
    fail("tree_info lists " + std::to_string(info.size()) + " trees, the model holds " + std::to_string(trees.size()));
  // xgboost reads this count when it loads the model; it must agree with the trees present.
  if (count_text(model.at("gbtree_model_param").at("num_trees"), "num_trees") != trees.size())
    fail("num_trees says " + model.at("gbtree_model_param").at("num_trees").dump().substr(0, 40) + ", the model holds " +
         std::to_string(trees.size()) + " trees");
  return model;
}

// A tree's node arrays in xgboost's JSON, under the names this reader gives them.
struct XgbTreeArrays {
  const FloatJson& left;
  const FloatJson& right;
  const FloatJson& feature;
  const FloatJson& value;
  const FloatJson& dleft;
};

XgbTreeArrays xgb_tree_arrays(const FloatJson& tree) {
  return {tree.at("left_children"), tree.at("right_children"), tree.at("split_indices"), tree.at("split_conditions"),
          tree.at("default_left")};
}

// Checks one tree's node arrays for a forest already holding `nodes_before` nodes, then walks
// it from the root: each node reached once (a tree), every index checked before use.
void check_xgb_tree(const FloatJson& tree, const std::string& where, std::size_t inputs, std::size_t nodes_before) {
  const auto& [left, right, feature, value, dleft] = xgb_tree_arrays(tree);
  const auto& type = tree.at("split_type");
  const std::size_t n = left.size();
  if (n == 0 || n > (1u << 24)) fail(where + "has " + std::to_string(n) + " nodes");
  if (nodes_before + n > (1u << 30)) fail(where + "the forest has more than 2^30 nodes");
  for (const auto* a : {&right, &feature, &value, &dleft, &type})
    if (!a->is_array() || a->size() != n) fail(where + "its node arrays differ in length");
  std::vector<char> seen(n, 0);
  std::vector<std::pair<std::int64_t, int>> stack{{0, 0}};
  while (!stack.empty()) {
    const auto [i, depth] = stack.back();
    stack.pop_back();
    const std::string at = where + "node " + std::to_string(i) + ": ";
    if (seen[static_cast<std::size_t>(i)]) fail(at + "reached twice; not a tree");
    seen[static_cast<std::size_t>(i)] = 1;
    if (depth > 64) fail(at + "deeper than 64");
    const auto l = integer(left[static_cast<std::size_t>(i)], at + "left child");
    const auto r = integer(right[static_cast<std::size_t>(i)], at + "right child");
    integer(dleft[static_cast<std::size_t>(i)], at + "default_left");
    const float v = value[static_cast<std::size_t>(i)].get<float>();
    if (!std::isfinite(v)) fail(at + "value is not finite");
    if (l == -1 && r == -1) continue;
    for (const auto c : {l, r})
      if (c <= 0 || c >= static_cast<std::int64_t>(n))
        fail(at + "child " + std::to_string(c) + " is out of range (the tree has " + std::to_string(n) + " nodes)");
    if (integer(type[static_cast<std::size_t>(i)], at + "split_type") != 0) fail(at + "categorical splits are not supported");
    const auto k = integer(feature[static_cast<std::size_t>(i)], at + "split index");
    if (k < 0 || static_cast<std::size_t>(k) >= inputs)
      fail(at + "splits on feature " + std::to_string(k) + " of " + std::to_string(inputs));
    stack.emplace_back(l, depth + 1);
    stack.emplace_back(r, depth + 1);
  }
}

// Appends a checked tree's nodes to `nodes`, laid out breadth first with each node's two children
// side by side (right = left + 1): 12-byte nodes, the top levels of a tree in a few cache lines.
// `Node` is XgbForest's node, deduced; `default_left` is its flag for a NaN going left.
template <class Node>
void lay_out_xgb_tree(const FloatJson& tree, std::vector<Node>& nodes, std::uint32_t default_left) {
  const auto& [left, right, feature, value, dleft] = xgb_tree_arrays(tree);
  const std::size_t base = nodes.size();
  nodes.emplace_back();
  std::vector<std::pair<std::size_t, std::size_t>> queue{{0, base}};  // (xgboost's, ours)
  for (std::size_t q = 0; q < queue.size(); ++q) {
    const auto [i, slot] = queue[q];
    Node& node = nodes[slot];
    node.value = value[i].get<float>();
    const auto l = left[i].get<std::int64_t>();  // checked by check_xgb_tree
    if (l == -1) continue;
    const auto children = nodes.size();
    node.left = static_cast<std::int32_t>(children);
    node.feature = static_cast<std::uint32_t>(feature[i].get<std::int64_t>()) | (dleft[i].get<int>() != 0 ? default_left : 0u);
    nodes.emplace_back();
    nodes.emplace_back();
    queue.emplace_back(static_cast<std::size_t>(l), children);
    queue.emplace_back(static_cast<std::size_t>(right[i].get<std::int64_t>()), children + 1);
  }
}

}  // namespace

XgbForest XgbForest::parse(std::string_view text, std::size_t inputs, std::size_t outputs) {
  const FloatJson j = parse_xgb_json(text);
  XgbForest f;
  if (outputs == 0 || outputs > kMaxOutputs)
    fail("a model predicts 1 to " + std::to_string(kMaxOutputs) + " outputs, not " + std::to_string(outputs));
  if (inputs == 0 || inputs > kMaxInputs)
    fail("a model reads 1 to " + std::to_string(kMaxInputs) + " inputs, not " + std::to_string(inputs));
  f.outputs_ = outputs;
  try {
    const FloatJson& model = read_xgb_model(j, inputs, outputs, f.base_score_);
    const auto& trees = model.at("trees");
    const auto& info = model.at("tree_info");
    for (std::size_t t = 0; t < trees.size(); ++t) {
      const std::string where = "tree " + std::to_string(t) + ": ";
      const auto target = integer(info[t], where + "tree_info");
      if (target < 0 || static_cast<std::size_t>(target) >= outputs)
        fail(where + "target " + std::to_string(target) + " is not below " + std::to_string(outputs));
      check_xgb_tree(trees[t], where, inputs, f.nodes_.size());
      const auto base = static_cast<std::uint32_t>(f.nodes_.size());
      lay_out_xgb_tree(trees[t], f.nodes_, kDefaultLeft);
      f.roots_.push_back(base);
      f.targets_.push_back(static_cast<std::uint32_t>(target));
    }
  } catch (const FloatJson::exception& e) {
    fail(std::string("malformed xgboost model: ") + e.what());
  } catch (const std::logic_error& e) {  // std::stof on a bad base_score
    fail(std::string("malformed xgboost model parameter: ") + e.what());
  }
  return f;
}

void XgbForest::predict(std::span<const double> x, std::span<double> y) const {
  float in[kMaxInputs];
  for (std::size_t j = 0; j < x.size() && j < kMaxInputs; ++j) in[j] = static_cast<float>(x[j]);
  float sum[kMaxOutputs];
  for (std::size_t k = 0; k < outputs_; ++k) sum[k] = base_score_;
  // A block of trees walked one level at a time: their loads are independent, so the cache
  // misses of a deep forest overlap instead of queueing one after another.
  constexpr std::size_t kBlock = 16;
  const Node* at[kBlock];
  for (std::size_t begin = 0; begin < roots_.size(); begin += kBlock) {
    const std::size_t n = std::min(kBlock, roots_.size() - begin);
    for (std::size_t i = 0; i < n; ++i) at[i] = &nodes_[roots_[begin + i]];
    for (bool moving = true; moving;) {
      moving = false;
      for (std::size_t i = 0; i < n; ++i) {
        const Node* node = at[i];
        if (node->left < 0) continue;
        const float v = in[node->feature & ~kDefaultLeft];
        const bool go_left = std::isnan(v) ? (node->feature & kDefaultLeft) != 0 : v < node->value;
        at[i] = &nodes_[static_cast<std::size_t>(node->left + (go_left ? 0 : 1))];
        moving = true;
      }
    }
    for (std::size_t i = 0; i < n; ++i) sum[targets_[begin + i]] += at[i]->value;  // in tree order, as xgboost sums
  }
  for (std::size_t k = 0; k < outputs_; ++k) y[k] = sum[k];
}

}  // namespace dicestack::detail
