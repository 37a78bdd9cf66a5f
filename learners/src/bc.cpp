#include <dicestack/learners/learner.hpp>

namespace dicestack {
namespace {

// Behaviour cloning: fit the regressor on every demonstrated (state, action) pair (paper VI-A;
// DAgger with beta = 0).
class BehaviourCloning final : public Learner {
 public:
  using Learner::Learner;
  LearnResult learn(const LearnContext& c) const override {
    if (c.progress) c.progress({"fit", 1, 1, 0, 1});
    LearnResult r;
    r.model = fit_model(c, c.demos, c.seed);
    r.model->record["learner"] = "bc";
    if (c.progress) c.progress({"fit", 1, 1, 1, 1});
    return r;
  }
};

}  // namespace

void register_bc(LearnerRegistry& r) {
  r.add({"bc", "behaviour cloning: fit the regressor on all demonstration pairs", {},
         [](std::string n, Params p) { return std::make_unique<BehaviourCloning>(std::move(n), std::move(p)); }});
}

}  // namespace dicestack
