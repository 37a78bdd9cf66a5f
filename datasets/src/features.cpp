#include <dicestack/datasets/features.hpp>

#include <algorithm>
#include <array>
#include <memory>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

namespace si = state_index;

// The built-in maps differ only in which blocks follow the current state.
struct Blocks {
  bool clock = false;
  bool start = false;
  bool previous = false;
  bool start_state = false;  // the whole start state instead of its two summary numbers
  bool open_loop = false;    // no current state: the clock and the start alone choose the action
};

class BuiltinFeatureMap final : public FeatureMap {
 public:
  BuiltinFeatureMap(std::string name, std::string description, Blocks blocks)
      : name_(std::move(name)), description_(std::move(description)), blocks_(blocks) {}

  std::string name() const override { return name_; }
  int version() const override { return 1; }
  std::string description() const override { return description_; }

  std::size_t width() const override {
    return (blocks_.open_loop ? 0 : kStateDim) + (blocks_.clock ? 1 : 0) + (blocks_.start ? 2 : 0) + (blocks_.previous ? kStateDim : 0) +
           (blocks_.start_state ? kStateDim : 0);
  }

  std::vector<std::string> column_names() const override {
    std::vector<std::string> out;
    if (!blocks_.open_loop)
      for (auto n : state_names()) out.emplace_back(n);
    if (blocks_.clock) out.emplace_back("t");
    if (blocks_.start) out.insert(out.end(), {"start_cup_x", "start_dice_mean_x"});
    if (blocks_.previous)
      for (auto n : state_names()) out.push_back("prev_" + std::string(n));
    if (blocks_.start_state)
      for (auto n : state_names()) out.push_back("start_" + std::string(n));
    return out;
  }

  void compute(const History& h, std::span<double> out) const override {
    const State& s = h.current();
    std::size_t at = 0;
    if (!blocks_.open_loop) {
      std::copy(s.begin(), s.end(), out.begin());
      at = kStateDim;
    }
    if (blocks_.clock) out[at++] = static_cast<double>(h.t());
    if (blocks_.start) {
      const State& s0 = h.start();
      double dice = 0.0;
      for (std::size_t i = 0; i < kDiceCount; ++i) dice += s0[si::die(i)];
      out[at++] = s0[si::kCupX];
      out[at++] = dice / static_cast<double>(kDiceCount);
    }
    if (blocks_.previous) {
      const State& p = h.states.size() >= 2 ? h.states[h.states.size() - 2] : s;
      std::copy(p.begin(), p.end(), out.begin() + static_cast<std::ptrdiff_t>(at));
      at += kStateDim;
    }
    if (blocks_.start_state) std::copy(h.start().begin(), h.start().end(), out.begin() + static_cast<std::ptrdiff_t>(at));
  }

 private:
  std::string name_, description_;
  Blocks blocks_;
};

const std::vector<std::unique_ptr<BuiltinFeatureMap>>& builtin_maps() {
  static const auto* maps = [] {
    auto* v = new std::vector<std::unique_ptr<BuiltinFeatureMap>>;
    v->push_back(std::make_unique<BuiltinFeatureMap>("state", "the 24 state numbers (the paper's input)", Blocks{}));
    v->push_back(std::make_unique<BuiltinFeatureMap>("state+clock", "the state and the step index t",
                                                     Blocks{true, false, false}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "state+clock+start", "the state, t, and the start's cup x and mean die x", Blocks{true, true, false}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "state+history", "the state and the previous state (the start repeated at t = 0)", Blocks{false, false, true}));
    v->push_back(std::make_unique<BuiltinFeatureMap>("state+clock+start_state", "the state, t and the whole start state",
                                                     Blocks{true, false, false, true}));
    v->push_back(std::make_unique<BuiltinFeatureMap>(
        "clock+start_state", "open loop: t and the whole start state, not the current state (a pattern chosen at the start)",
        Blocks{true, false, false, true, true}));
    return v;
  }();
  return *maps;
}

}  // namespace

const FeatureMap& feature_map(std::string_view name) {
  for (const auto& m : builtin_maps())
    if (m->name() == name) return *m;
  std::string known;
  for (const auto& n : feature_map_names()) known += (known.empty() ? "" : ", ") + n;
  throw ConfigError("unknown feature map \"" + std::string(name) + "\"; known: " + known);
}

std::vector<std::string> feature_map_names() {
  std::vector<std::string> out;
  for (const auto& m : builtin_maps()) out.push_back(m->name());
  return out;
}

const FeatureMap& state_features() { return *builtin_maps().front(); }

}  // namespace dicestack
