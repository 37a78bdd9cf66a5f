// The regressor registry: built-ins and plugins listed with their sources, names and parameters
// checked, the plugin handshake, and every threads parameter giving one model.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <dicestack/core/error.hpp>
#include <dicestack/regressors/params.hpp>
#include <dicestack/regressors/registry.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/regressors.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;
using test::inputs;
using test::registered_with_plugin;
using test::target;

TEST(Registry, EveryThreadsParameterGivesTheSameModelOnAnyCount) {
  const Matrix x = inputs(300, 24, 7), probe = inputs(10, 24, 8);
  int with_threads = 0;
  for (const auto& name : registered_with_plugin()) {
    const auto& params = RegressorRegistry::global().info(name).params;
    if (std::none_of(params.begin(), params.end(), [](const ParamSpec& p) { return p.name == "threads"; })) continue;
    ++with_threads;
    auto one = RegressorRegistry::global().create(name, {"threads=1"});
    auto two = RegressorRegistry::global().create(name, {"threads=2"});
    one->fit(x, target(x, false), 42);
    two->fit(x, target(x, false), 42);
    EXPECT_EQ(one->predict(probe), two->predict(probe)) << name;
    EXPECT_EQ(one->save_payload(), two->save_payload()) << name;
  }
  EXPECT_EQ(with_threads, 3);  // gbt, random_forest, rbf_svr
}

TEST(Registry, ListsBuiltinsAndPluginWithSources) {
  const auto& reg = RegressorRegistry::global();
  for (const char* n : {"gbt", "knn", "linear_svr", "mlp", "random_forest", "rbf_svr", "ridge"})
    EXPECT_TRUE(reg.contains(n)) << n;
  EXPECT_EQ(reg.info("knn").source, "built-in");
  EXPECT_THAT(reg.info("ridge").source, HasSubstr("plugin "));
  EXPECT_THAT(test::error_of([&] { reg.create("rbf-svr"); }),
              HasSubstr("unknown regressor \"rbf-svr\"; registered: gbt, knn, linear_svr, mlp, random_forest, rbf_svr"));
  EXPECT_THAT(test::error_of([&] { reg.create("knn", {"k=three"}); }),
              HasSubstr("knn: parameter \"k\" expects an integer, got \"three\""));
  EXPECT_THAT(test::error_of([&] { reg.create("rbf_svr", {"gamma=-1"}); }),
              HasSubstr("rbf_svr: parameter \"gamma\" must be >= 0, got -1"));
  EXPECT_THAT(test::error_of([&] { reg.create("rbf_svr", {"gama=1"}); }),
              HasSubstr("rbf_svr: unknown parameter \"gama\" (parameters: c, epsilon, gamma, tol, threads)"));
  EXPECT_THAT(test::error_of([&] { reg.create("knn", {"k"}); }), HasSubstr("knn: \"k\" is not key=value"));
}

TEST(Registry, PluginHandshakeRefusesWhatItCannotUse) {
  auto& reg = RegressorRegistry::global();
  const std::string abi = test::error_of([&] { reg.load_plugin(DICESTACK_ABI99_PLUGIN); });
  EXPECT_THAT(abi, HasSubstr("built for dicestack ABI 99"));
  EXPECT_THAT(abi, HasSubstr("this is ABI 1"));
  EXPECT_THAT(abi, HasSubstr("rebuild it with find_package(dicestack"));
  EXPECT_THROW(reg.load_plugin(DICESTACK_ABI99_PLUGIN), PluginError);
  EXPECT_THAT(test::error_of([&] { reg.load_plugin(DICESTACK_NOT_A_PLUGIN); }),
              HasSubstr("not a dicestack plugin (no symbol dicestack_plugin_v1)"));
  EXPECT_THAT(test::error_of([&] { reg.load_plugin(DICESTACK_DATA_ENTRY); }),
              HasSubstr("dicestack_plugin_v1 is not a function; not a dicestack plugin"));
  EXPECT_THAT(test::error_of([&] { reg.load_plugin(DICESTACK_NULL_RECORD); }),
              HasSubstr("its plugin record has a null field"));
  EXPECT_THAT(test::error_of([&] { reg.load_plugin(DICESTACK_DUPLICATE_PLUGIN); }),
              HasSubstr("regressor \"knn\" registered twice (built-in, and plugin "));
  const fs::path junk = test::scratch_path("dicestack_not_a_library.so");
  std::ofstream(junk) << "not an ELF file";
  EXPECT_THAT(test::error_of([&] { reg.load_plugin(junk); }), HasSubstr("cannot load:"));
  EXPECT_THAT(test::error_of([&] { reg.load_plugin("/nonexistent/libx.so"); }), HasSubstr("no such file"));
  fs::remove(junk);
}

}  // namespace
}  // namespace dicestack
