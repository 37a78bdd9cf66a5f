#include <gtest/gtest.h>

#include <dicestack/datasets/dataset.hpp>
#include <dicestack/datasets/episode_bytes.hpp>
#include <dicestack/learners/learner.hpp>
#include <dicestack/learners/record.hpp>
#include <dicestack/regressors/model.hpp>
#include <dicestack/test/episodes.hpp>
#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

// What travels between ranks must come back bit for bit, or results would change with the rank count.
TEST(ClusterBytes, EpisodeRoundTripsEveryField) {
  auto eps = record_expert("scripted", {}, test::short_world(40), test::record_request(2, 11, 1));
  eps[1].final_state.reset();
  eps[1].rewards.clear();
  eps[1].name = "episode_0001";
  eps[0].links.assign(eps[0].size(), ArmLinks{{1, 2, 3}, {4, 5, 6}});  // an arm's joint readings travel too
  for (const Episode& e : eps) {
    test::expect_same_episode(episode_from_bytes(episode_to_bytes(e)), e);
  }
  EXPECT_THROW(episode_from_bytes(episode_to_bytes(eps[0]).substr(0, 100)), Error);
}

// A model refitted on the root reaches the other ranks as model_to_bytes: parsed back, it acts
// exactly as the original and writes the same bytes again.
TEST(ClusterBytes, ModelBytesRoundTripForEveryRegressor) {
  LearnContext c;
  c.world = test::short_world(40);
  c.demos = record_expert("scripted", {}, c.world, test::record_request(2, 3, 1));
  for (const std::string& name : RegressorRegistry::global().names()) {
    c.regressor = name;
    c.regressor_sets = name == "mlp" ? std::vector<std::string>{"layers=2", "width=8"} : std::vector<std::string>{};
    const auto model = fit_model(c, c.demos, 5);
    const std::string bytes = model_to_bytes(*model);
    const Model back = parse_model_file(bytes, "test");
    EXPECT_EQ(model_to_bytes(back), bytes) << name;
    const Dataset d = make_dataset(c.demos, feature_map("state"));
    EXPECT_TRUE(back.predict(d.x) == model->predict(d.x)) << name;
    for (const auto& s : c.demos[0].states) EXPECT_EQ(back.act(s), model->act(s)) << name;
  }
}

}  // namespace
}  // namespace dicestack
