// One suite run over every registered regressor, plugins included (STYLE 13).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/model.hpp>
#include <dicestack/regressors/registry.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

// Every registered name, after loading the example ridge plugin into the global registry.
std::vector<std::string> registered_with_plugin() {
  RegressorRegistry::global().load_plugin(DICESTACK_RIDGE_PLUGIN);
  return RegressorRegistry::global().names();
}

// A smooth nonlinear map from d inputs to 3 outputs (linear when `linear`).
Matrix target(const Matrix& x, bool linear) {
  Matrix y(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    const auto r = x.row(i);
    y(i, 0) = 0.8 * r(0) - 0.5 * r(1) + 0.3 * r(5);
    y(i, 1) = linear ? 0.4 * r(2) + 0.2 * r(3) - 0.1 : std::sin(1.5 * r(2)) + 0.3 * r(3) * r(4);
    y(i, 2) = linear ? -0.6 * r(0) + 0.7 * r(7) : std::tanh(r(0) + r(6)) - 0.2 * r(7) * r(7);
  }
  return y;
}

Matrix inputs(Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  Rng rng(seed);
  Matrix x(n, d);
  for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = rng.normal();
  return x;
}

class Conformance : public ::testing::TestWithParam<std::string> {
 protected:
  std::unique_ptr<Regressor> make(const std::vector<std::string>& sets = {}) const {
    return RegressorRegistry::global().create(GetParam(), sets);
  }
};

TEST_P(Conformance, ShapesAndRowEqualsBatch) {
  const Matrix x = inputs(400, 24, 1), probe = inputs(20, 24, 2);
  auto r = make();
  EXPECT_FALSE(r->fitted());
  r->fit(x, target(x, false), 3);
  ASSERT_TRUE(r->fitted());
  EXPECT_EQ(r->input_dim(), 24u);
  EXPECT_EQ(r->output_dim(), 3u);
  const Matrix batch = r->predict(probe);
  ASSERT_EQ(batch.rows(), 20);
  ASSERT_EQ(batch.cols(), 3);
  double row[3];
  for (Eigen::Index i = 0; i < probe.rows(); ++i) {
    r->predict_row({probe.row(i).data(), 24}, row);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(row[j], batch(i, j), 1e-9 * (1.0 + std::abs(row[j]))) << "row " << i;
  }
}

TEST_P(Conformance, WideInputsArePredictedOrRefusedByName) {
  // 80 input columns: more than any fixed-size scratch row a hot path might keep.
  const Matrix x = inputs(200, 80, 11), probe = inputs(5, 80, 12);
  auto r = make();
  try {
    r->fit(x, target(x, false), 3);
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr(GetParam() + ": 80 input dimensions"));
    return;
  }
  const Matrix batch = r->predict(probe);
  double row[3];
  for (Eigen::Index i = 0; i < probe.rows(); ++i) {
    r->predict_row({probe.row(i).data(), 80}, row);
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(row[j], batch(i, j), 1e-9 * (1.0 + std::abs(row[j]))) << "row " << i;
  }
}

TEST_P(Conformance, SaveThenLoadPredictsIdentically) {
  const Matrix x = inputs(300, 24, 4), probe = inputs(15, 24, 5);
  auto r = make();
  r->fit(x, target(x, false), 6);
  const std::string payload = r->save_payload();
  auto back = make();
  back->load_payload(payload, 24, 3);
  EXPECT_EQ(back->predict(probe), r->predict(probe));
  // Through a model file, with standardisers and checksum.
  Model model = Model::train(make(), x, target(x, false), 6);
  const fs::path path = test::scratch_path("dicestack_conformance_" + GetParam() + ".dsm");
  save_model(model, path);
  const Model loaded = load_model(path);
  EXPECT_EQ(loaded.predict(probe), model.predict(probe));
  State s{};
  for (std::size_t j = 0; j < kStateDim; ++j) s[j] = probe(0, static_cast<Eigen::Index>(j));
  EXPECT_EQ(loaded.act(s), model.act(s));
  fs::remove(path);
}

TEST_P(Conformance, SameSeedSameModel) {
  const Matrix x = inputs(300, 24, 7), probe = inputs(10, 24, 8);
  auto a = make(), b = make();
  a->fit(x, target(x, false), 42);
  b->fit(x, target(x, false), 42);
  EXPECT_EQ(a->predict(probe), b->predict(probe));
}

TEST_P(Conformance, RejectsBadInputWithItsName) {
  const std::string name = GetParam();
  Matrix x = inputs(50, 24, 9);
  const Matrix y = target(x, true);
  auto r = make();
  EXPECT_THAT(test::error_of([&] { r->predict(x); }), HasSubstr(name + ": predict called before fit"));
  x(7, 3) = std::nan("");
  EXPECT_THAT(test::error_of([&] { r->fit(x, y, 1); }), HasSubstr(name + ": input row 7 holds NaN"));
  x(7, 3) = 0.0;
  EXPECT_THAT(test::error_of([&] { r->fit(x, Matrix(49, 3), 1); }), HasSubstr(name + ": 50 input rows but 49 labels"));
  r->fit(x, y, 1);
  double out[3];
  const std::vector<double> short_row(23, 0.0);
  EXPECT_THAT(test::error_of([&] { r->predict_row(short_row, out); }), HasSubstr(name + ": predict_row got 23 inputs"));
  EXPECT_THROW(r->predict(Matrix(2, 25)), InputError);
  EXPECT_THAT(test::error_of([&] { make({"no_such_parameter=1"}); }),
              HasSubstr(name + ": unknown parameter \"no_such_parameter\""));
  const auto& schema = RegressorRegistry::global().info(name).params;
  for (const auto& p : schema) {
    if (p.type == dicestack::ParamType::integer || p.type == dicestack::ParamType::real) {
      const std::string msg = test::error_of([&] { make({p.name + "=1e308x"}); });
      EXPECT_THAT(msg, HasSubstr(name + ": parameter \"" + p.name + "\" expects"));
      if (p.min > -1e300) {
        const std::string low = test::error_of([&] { make({p.name + "=-1e301"}); });
        EXPECT_THAT(low, HasSubstr(name + ": parameter \"" + p.name + "\""));
        EXPECT_THAT(low, HasSubstr("-1e301"));
      }
    }
  }
}

TEST_P(Conformance, LearnsAKnownFunction) {
  const std::string name = GetParam();
  const bool linear = name == "linear_svr" || name == "ridge";
  const Matrix x = inputs(1500, 24, 10), test_x = inputs(300, 24, 11);
  // A smooth function of few inputs that varies along the data's spread.
  Matrix xs = x, ts = test_x;
  xs.rightCols(16).setZero();
  ts.rightCols(16).setZero();
  auto r = make();
  r->fit(xs, target(xs, linear), 12);
  const Matrix truth = target(ts, linear), pred = r->predict(ts);
  const double err = (pred - truth).cwiseAbs().mean();
  const double spread = (truth.rowwise() - truth.colwise().mean()).cwiseAbs().mean();
  EXPECT_LT(err, (linear ? 0.05 : 0.45) * spread) << name << ": mean |error| " << err << " vs spread " << spread;
}

INSTANTIATE_TEST_SUITE_P(AllRegistered, Conformance, ::testing::ValuesIn(registered_with_plugin()),
                         [](const auto& param_info) { return param_info.param; });

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

TEST(ModelFile, TruncatedCorruptedOrForeignFilesAreRejected) {
  const Matrix x = inputs(100, 24, 13);
  const Model model = Model::train(RegressorRegistry::global().create("knn"), x, target(x, true), 1);
  const fs::path path = test::scratch_path("dicestack_model_file.dsm");
  save_model(model, path);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto rewrite = [&](const std::string& content) { std::ofstream(path, std::ios::binary | std::ios::trunc) << content; };
  rewrite(bytes.substr(0, bytes.size() - 100));
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("truncated: the payload has"));
  std::string flipped = bytes;
  flipped[flipped.size() - 10] ^= 0x55;
  rewrite(flipped);
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("corrupted: the payload's checksum"));
  rewrite("hello\n");
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("not a dicestack model"));
  std::string newer = bytes;
  newer.replace(newer.find("\"version\":2"), 11, "\"version\":7");
  rewrite(newer);
  EXPECT_THAT(test::error_of([&] { load_model(path); }),
              HasSubstr("format version 7 is newer than this dicestack reads (2); upgrade dicestack"));
  std::string dims = bytes;
  dims.replace(dims.find("\"state_dim\":24"), 14, "\"state_dim\":26");
  rewrite(dims);
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("the header's checksum does not match"));
  std::string unknown = bytes;
  unknown.replace(unknown.find("\"regressor\":\"knn\""), 17, "\"regressor\":\"zzz\"");
  rewrite(unknown);
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("the header's checksum does not match"));
  EXPECT_EQ(test::error_of([&] { load_model("/nonexistent/model.dsm"); }),
            "/nonexistent/model.dsm: cannot open for reading: No such file or directory");
  rewrite(bytes);
  fs::permissions(path, fs::perms::none);
  const auto denied = test::unprivileged([&] { return test::error_of([&] { load_model(path); }); });
  if (denied) {
    EXPECT_EQ(*denied, path.string() + ": cannot open for reading: Permission denied");
  }
  fs::remove(path);
  fs::create_directory(path);
  EXPECT_EQ(test::error_of([&] { load_model(path); }), path.string() + ": read failed: Is a directory");
  fs::remove(path);
}

}  // namespace
}  // namespace dicestack
