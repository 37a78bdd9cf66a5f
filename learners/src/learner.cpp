#include <dicestack/learners/learner.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/dataset.hpp>

namespace dicestack {

void register_bc(LearnerRegistry&);
void register_dagger(LearnerRegistry&);

LearnerRegistry& LearnerRegistry::global() {
  static LearnerRegistry* registry = [] {
    auto* r = new LearnerRegistry;
    register_bc(*r);
    register_dagger(*r);
    return r;
  }();
  return *registry;
}

void LearnerRegistry::add(LearnerInfo info) {
  if (entries_.contains(info.name)) throw ConfigError("learner \"" + info.name + "\" registered twice");
  std::string name = info.name;
  entries_.emplace(std::move(name), std::move(info));
}

const LearnerInfo& LearnerRegistry::info(std::string_view name) const {
  const auto it = entries_.find(name);
  if (it == entries_.end()) {
    std::string list;
    for (const auto& n : names()) list += (list.empty() ? "" : ", ") + n;
    throw ConfigError("unknown learner \"" + std::string(name) + "\"; registered: " + list);
  }
  return it->second;
}

std::unique_ptr<Learner> LearnerRegistry::create(std::string_view name, const std::vector<std::string>& assignments) const {
  const LearnerInfo& i = info(name);
  return i.factory(i.name, Params(i.params, assignments, i.name));
}

std::vector<std::string> LearnerRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [name, info] : entries_) out.push_back(name);
  return out;
}

std::shared_ptr<Model> fit_model(const LearnContext& c, const std::vector<Episode>& data, std::uint64_t seed) {
  if (data.empty()) throw InputError("no demonstrations to learn from");
  const Dataset d = make_dataset(data);
  auto model = std::make_shared<Model>(Model::train(c.registry->create(c.regressor, c.regressor_sets), d.x, d.y, seed));
  model->record["regressor_params"] = model->regressor().params().summary();
  model->record["rows"] = std::to_string(d.rows());
  model->record["episodes"] = std::to_string(d.episodes());
  model->record["seed"] = std::to_string(seed);
  return model;
}

}  // namespace dicestack
