// Model files carry their feature map (format 2) and still read format 1.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <tuple>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/hash.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/regressors/model.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/regressors.hpp>

namespace dicestack {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
namespace fs = std::filesystem;
using test::inputs;
using test::target;

Matrix random_rows(Eigen::Index n, Eigen::Index d, std::uint64_t seed) {
  Rng rng(seed);
  Matrix x(n, d);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < d; ++j) x(i, j) = rng.uniform(-1.0, 1.0);
  return x;
}

Matrix model_labels(const Matrix& x) {
  Matrix y(x.rows(), 3);
  for (Eigen::Index i = 0; i < x.rows(); ++i) y.row(i) << x(i, 0) - x(i, x.cols() - 1), 0.5 * x(i, 1), x(i, 2);
  return y;
}

fs::path temp_model(const std::string& name) {
  return fs::temp_directory_path() / ("dicestack_model_" + name + "_" + std::to_string(getpid()) + ".dsm");
}

// Splits a model file into its JSON header and payload, and writes them back.
std::pair<nlohmann::json, std::string> read_parts(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string header;
  std::getline(in, header);
  std::ostringstream rest;
  rest << in.rdbuf();
  return {nlohmann::json::parse(header), rest.str()};
}
void write_parts(const fs::path& path, const nlohmann::json& header, const std::string& payload) {
  std::ofstream(path, std::ios::binary) << header.dump() << '\n' << payload;
}
// Recomputes a version 2 header's whole-file checksum after an edit (a deliberately crafted file).
void reseal(nlohmann::json& header, const std::string& payload) {
  header.erase("checksum");
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a(header.dump() + '\n' + payload)));
  header["checksum"] = hex;
}

TEST(ModelFile, StoresItsFeatureMapAndActsOnHistories) {
  const FeatureMap& f = feature_map("state+clock+start");
  const Matrix x = random_rows(200, 27, 1);
  const Model m = Model::train(RegressorRegistry::global().create("linear_svr"), x, model_labels(x), 3, nullptr, f);
  const fs::path path = temp_model("features");
  save_model(m, path);
  const Model back = load_model(path);
  EXPECT_EQ(back.features().name(), "state+clock+start");
  const auto [header, payload] = read_parts(path);
  EXPECT_EQ(header.at("version"), 2);
  EXPECT_EQ(header.at("input_dim"), 27);
  // The clock and the start reach the regressor: the same state at another step acts differently.
  const std::vector<State> at0{State{}}, at5(6, State{});
  EXPECT_EQ(back.act(History{at0, {}}), m.act(History{at0, {}}));
  EXPECT_NE(back.act(History{at0, {}}), back.act(History{at5, {}}));
  fs::remove(path);
}

TEST(ModelFile, ATorquePolicyIsVersionThreeWithFourAnswersAndReadsBack) {
  const FeatureMap& f = feature_map("state+links+clock/torque");
  const Matrix x = random_rows(200, static_cast<Eigen::Index>(f.width()), 4);
  Matrix y(x.rows(), 4);
  for (Eigen::Index i = 0; i < x.rows(); ++i) y.row(i) << 100 * x(i, 0), -50 * x(i, 25), 20 * x(i, 30), 5.0;
  const Model m = Model::train(RegressorRegistry::global().create("linear_svr"), x, y, 3, nullptr, f);
  const fs::path path = temp_model("torque");
  save_model(m, path);
  const auto [header, payload] = read_parts(path);
  EXPECT_EQ(header.at("version"), 3) << "a map reading links and answering torques needs the newer format";
  EXPECT_EQ(header.at("action_dim"), 4);
  EXPECT_EQ(header.at("action_names")[3], "tau3");
  const Model back = load_model(path);
  const std::vector<State> states{State{}};
  const std::vector<ArmLinks> links{{{0.1, 0.2, 0.3}, {0.0, 0.0, 0.0}}};
  const Action a = back.act(History{states, {}, {}, {}, links});
  EXPECT_EQ(a.kind(), ActionKind::joint_torque);
  EXPECT_EQ(a, m.act(History{states, {}, {}, {}, links}));
  // Four answers under a map of three is a broken file, said as such.
  auto [edited, bytes] = read_parts(path);
  edited["features"] = "state+links+clock";
  reseal(edited, bytes);
  write_parts(path, edited, bytes);
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("predicts 4-d actions, feature map \"state+links+clock\" answers 3-d"));
  // A version 2 file never held such a map.
  auto [older, payload2] = read_parts(path);
  older["features"] = "state+links+clock/torque";
  older["version"] = 2;
  reseal(older, payload2);
  write_parts(path, older, payload2);
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("came with format version 3; this file says 2"));
  // Without the fitted data's widths: 3 labels for a torque map.
  EXPECT_THAT(test::error_of([&] { Model::train(RegressorRegistry::global().create("linear_svr"), x, model_labels(x), 3, nullptr, f); }),
              HasSubstr("to 4 action values"));
  fs::remove(path);
}

// An "/osc" map answered the pose alone at version 1 and answers the posture too at version 2:
// a model of the older map is refused by name, not run with its answers misread.
TEST(ModelFile, AnOscModelOfAnOlderMapVersionIsRefusedAndSaysToTrainAgain) {
  const FeatureMap& f = feature_map("state+links+clock/osc");
  ASSERT_EQ(f.version(), 2);
  const Matrix x = random_rows(100, static_cast<Eigen::Index>(f.width()), 6);
  Matrix y(x.rows(), 4);
  for (Eigen::Index i = 0; i < x.rows(); ++i) y.row(i) << x(i, 0), x(i, 1), x(i, 2), 0.5 * x(i, 25);
  const fs::path path = temp_model("osc_v1");
  save_model(Model::train(RegressorRegistry::global().create("linear_svr"), x, y, 3, nullptr, f), path);
  EXPECT_NO_THROW(load_model(path));
  auto [header, payload] = read_parts(path);
  header["features_version"] = 1;
  reseal(header, payload);
  write_parts(path, header, payload);
  EXPECT_THAT(test::error_of([&] { load_model(path); }),
              AllOf(HasSubstr(path.string()), HasSubstr("\"state+links+clock/osc\" version 1 differs from this dicestack's (2)"),
                    HasSubstr("train the model again")));
  fs::remove(path);
}

TEST(ModelFile, AVelocityMapActsWithTheCupVelocityItsRegressorAnswersLessTheCupsVelocityNow) {
  // A regressor fitted on velocity labels answers a velocity; the model's action is that less the
  // current cup velocity, and the file keeps the map.
  const FeatureMap& f = feature_map("state/velocity");
  const Matrix x = random_rows(200, 24, 4);
  const Model m = Model::train(RegressorRegistry::global().create("linear_svr"), x, model_labels(x), 3, nullptr, f);
  const fs::path path = temp_model("velocity");
  save_model(m, path);
  const Model back = load_model(path);
  EXPECT_EQ(back.features().name(), "state/velocity");
  State s{};
  for (std::size_t j = 0; j < kStateDim; ++j) s[j] = 0.01 * static_cast<double>(j);
  Matrix row(1, 24);
  for (Eigen::Index j = 0; j < 24; ++j) row(0, j) = s[static_cast<std::size_t>(j)];
  const Matrix answer = back.predict(row);
  const Action a = back.act(s);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(a[k], answer(0, static_cast<Eigen::Index>(k)) - s[21 + k], 1e-12) << k;
  fs::remove(path);
}

TEST(ModelFile, RefusesAFeatureMapThatDoesNotMatchTheRegressorsWidth) {
  const Matrix x = random_rows(200, 24, 2);
  const fs::path path = temp_model("mismatch");
  save_model(Model::train(RegressorRegistry::global().create("linear_svr"), x, model_labels(x), 3), path);
  auto [header, payload] = read_parts(path);
  header["features"] = "state+clock";  // 25 inputs, but the regressor and the header say 24
  reseal(header, payload);
  write_parts(path, header, payload);
  const std::string error = test::error_of([&] { load_model(path); });
  EXPECT_THAT(error, HasSubstr(path.string() + ": the regressor reads 24 inputs, but feature map \"state+clock\" produces 25"));
  header["features"] = "state+tomorrow";
  reseal(header, payload);
  write_parts(path, header, payload);
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("feature map \"state+tomorrow\": unknown part \"tomorrow\""));
  EXPECT_THROW(load_model(path), InputError);
  fs::remove(path);
}

TEST(ModelFile, TheChecksumCoversTheHeader) {
  const Matrix x = random_rows(200, 24, 5);
  const fs::path path = temp_model("header");
  save_model(Model::train(RegressorRegistry::global().create("linear_svr"), x, model_labels(x), 3), path);
  auto [header, payload] = read_parts(path);
  header["x_standardizer"]["mean"][3] = 0.25;  // a changed standardiser, payload untouched
  write_parts(path, header, payload);
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr("corrupted: the header's checksum does not match"));
  for (const auto& [key, value] : {std::pair<const char*, nlohmann::json>{"version", 1.5}, {"payload_bytes", 122.5},
                                   {"payload_bytes", -1}, {"payload_bytes", 2000000000}}) {
    auto edited = read_parts(path).first;
    edited[key] = value;
    write_parts(path, edited, payload);
    const std::string error = test::error_of([&] { load_model(path); });
    EXPECT_THAT(error, HasSubstr(path.string())) << key;
    EXPECT_FALSE(error.empty()) << key << " " << value.dump();
  }
  fs::remove(path);
}

TEST(ModelFile, DeeplyNestedHeadersAreRefusedNotCrashed) {
  const fs::path path = temp_model("deep");
  std::ofstream(path) << "{\"format\":\"dicestack-model\",\"version\":" << std::string(200000, '[')
                      << std::string(200000, ']') << "}\n";
  EXPECT_THAT(test::error_of([&] { load_model(path); }), HasSubstr(path.string() + ": JSON nested deeper than 64 levels"));
  fs::remove(path);
  auto r = RegressorRegistry::global().create("gbt");
  EXPECT_THAT(test::error_of([&] { r->load_payload(std::string(100000, '[') + std::string(100000, ']'), 24, 3); }),
              HasSubstr("JSON nested deeper than 64 levels"));
}

TEST(ModelFile, MatrixPayloadShapesAreCheckedBeforeAllocating) {
  const Matrix x = random_rows(100, 24, 6);
  for (const char* name : {"linear_svr", "knn", "mlp"}) {
    auto r = RegressorRegistry::global().create(name);
    r->fit(x, model_labels(x), 1);
    std::string payload = r->save_payload();
    const std::uint64_t rows = 1ULL << 31;  // the first matrix's row count: 2^31 x cols doubles
    std::memcpy(payload.data() + 16, &rows, sizeof rows);
    auto back = RegressorRegistry::global().create(name);
    EXPECT_THAT(test::error_of([&] { back->load_payload(payload, 24, 3); }), HasSubstr("remaining bytes hold")) << name;
  }
}

TEST(ModelFile, RbfSvrPayloadCountsAreChecked) {
  const Matrix x = random_rows(40, 4, 9);
  auto r = RegressorRegistry::global().create("rbf_svr");
  r->fit(x, model_labels(x), 1);
  const std::string payload = r->save_payload();
  auto load = [&](const std::string& text, std::size_t inputs) {
    return test::error_of([&] { RegressorRegistry::global().create("rbf_svr")->load_payload(text, inputs, 3); });
  };
  EXPECT_EQ(load(payload, 4), "");
  EXPECT_THAT(load(payload, 24), HasSubstr("rbf_svr: model 0"));
  // Each YAML model edited inside its JSON string: counts that disagree with what follows.
  auto edited = [&](const std::string& from, const std::string& to) {
    nlohmann::json j = nlohmann::json::parse(payload);
    std::string yaml = j["models"][0];
    const auto at = yaml.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    yaml.replace(at, from.size(), to);
    j["models"][0] = yaml;
    return load(j.dump(), 4);
  };
  const auto sv_count = [&] {
    const std::string yaml = nlohmann::json::parse(payload)["models"][0];
    const auto at = yaml.find("sv_count: ");
    return yaml.substr(at, yaml.find('\n', at) - at);
  }();
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {sv_count, "sv_count: 2"}, {sv_count, "sv_count: 100000"}, {"var_count: 4", "var_count: 3"},
           {"var_count: 4", "var_count: 9"}, {"kernel:\n   type: RBF", "kernel:\n   type: LINEAR"},
           {"svmType: EPS_SVR", "svmType: NU_SVR"}}) {
    const std::string error = edited(from, to);
    EXPECT_THAT(error, HasSubstr("rbf_svr")) << from << " -> " << to;
  }
  const std::string sv_total = [&] {
    const std::string yaml = nlohmann::json::parse(payload)["models"][0];
    const auto at = yaml.find("sv_total: ");
    return yaml.substr(at, yaml.find('\n', at) - at);
  }();
  EXPECT_THAT(edited(sv_total, "sv_total: 100000"), HasSubstr("rbf_svr"));
  EXPECT_THAT(edited(sv_total, "sv_total: 1"), HasSubstr("rbf_svr"));
}

TEST(ModelFile, BadParametersAreRefusedNamingTheFile) {
  // Found by fuzz/model_file: a resealed header with "c": "0" gave the registry's ConfigError
  // ("rbf_svr: parameter ...") without the file's name.
  const Matrix x = random_rows(30, 24, 7);
  const fs::path path = temp_model("params");
  save_model(Model::train(RegressorRegistry::global().create("linear_svr"), x, model_labels(x), 3), path);
  const auto [original, payload] = read_parts(path);
  for (const auto& [key, value, expected] : {std::tuple<const char*, const char*, const char*>{
                                                 "epsilon", "-1", "parameter \"epsilon\" must be >= 0, got -1"},
                                             {"max_iter", "many", "parameter \"max_iter\" expects an integer"},
                                             {"gama", "1", "unknown parameter \"gama\""}}) {
    nlohmann::json header = original;
    header["params"][key] = value;
    reseal(header, payload);
    write_parts(path, header, payload);
    const std::string error = test::error_of([&] { load_model(path); });
    EXPECT_THAT(error, HasSubstr(path.string() + ": \"params\": linear_svr: " + expected)) << key;
    EXPECT_THROW(load_model(path), InputError) << key;
  }
  fs::remove(path);
}

TEST(ModelFile, VersionOneReadsAsTheStateMap) {
  const Matrix x = random_rows(200, 24, 4);
  const Model m = Model::train(RegressorRegistry::global().create("knn"), x, model_labels(x), 3);
  const fs::path path = temp_model("v1");
  save_model(m, path);
  auto [header, payload] = read_parts(path);
  for (const char* key : {"features", "features_version", "input_dim", "input_names", "checksum"}) header.erase(key);
  header["version"] = 1;
  write_parts(path, header, payload);
  const Model back = load_model(path);
  EXPECT_EQ(back.features().name(), "state");
  EXPECT_EQ(back.predict(x.topRows(5)), m.predict(x.topRows(5)));
  fs::remove(path);
}

// A stand-in for a Python regressor: its "pickle" is the mean of the labels, as text.
class MeanPickled final : public PickledRegressor {
 public:
  using PickledRegressor::PickledRegressor;
  std::string pickle() const override {
    std::ostringstream out;
    out << std::setprecision(17) << "mean " << mean_[0] << ' ' << mean_[1] << ' ' << mean_[2];
    return out.str();
  }
  std::string object_type() const override { return "tests.MeanPickled"; }
  void set(const std::array<double, 3>& mean) { mean_ = mean; }

 private:
  void do_fit(const Matrix&, const Matrix& y, std::uint64_t) override {
    for (Eigen::Index k = 0; k < 3; ++k) mean_[static_cast<std::size_t>(k)] = y.col(k).mean();
  }
  void do_predict_row(std::span<const double>, std::span<double> y) const override { std::copy(mean_.begin(), mean_.end(), y.begin()); }
  void do_load(std::string_view payload, std::size_t, std::size_t) override {
    if (!is_pickled_payload(payload)) throw InputError("not a pickled payload");
  }
  std::array<double, 3> mean_{};
};

PickleLoader mean_loader(int* calls) {
  return [calls](const std::string& name, const std::vector<std::string>& params, const std::string& bytes) {
    ++*calls;
    EXPECT_TRUE(params.empty());
    std::array<double, 3> mean{};
    std::istringstream in(bytes.substr(5));
    in >> mean[0] >> mean[1] >> mean[2];
    auto r = std::make_unique<MeanPickled>(name, Params());
    r->set(mean);
    return std::unique_ptr<Regressor>(std::move(r));
  };
}

TEST(ModelFile, PickledRegressorsKeepTheirPickleBesideTheModel) {
  const Matrix x = random_rows(50, 24, 5);
  const Model m = Model::train(std::make_unique<MeanPickled>("py_mean", Params()), x, model_labels(x), 3);
  const fs::path path = temp_model("pickled"), pkl = pickle_path(path);
  EXPECT_EQ(pkl.string(), path.string() + ".pkl");
  save_model(m, path);
  ASSERT_TRUE(fs::exists(pkl));
  EXPECT_TRUE(is_pickled_payload(read_parts(path).second));
  // Without a loader (the command line) it is refused, and the message says why.
  const std::string error = test::error_of([&] { load_model(path); });
  EXPECT_THAT(error, HasSubstr(path.string() + ": regressor \"py_mean\" is a Python object (tests.MeanPickled) pickled in " + pkl.string()));
  EXPECT_THAT(error, HasSubstr("unpickling runs code"));
  EXPECT_THAT(error, HasSubstr("allow_pickle=True"));
  EXPECT_THROW(load_model(path), InputError);
  int calls = 0;
  const Model back = load_model(path, RegressorRegistry::global(), mean_loader(&calls));
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(back.regressor().name(), "py_mean");
  EXPECT_EQ(back.predict(x.topRows(3)), m.predict(x.topRows(3)));
  // Saved again over its own files; a pickle that is not the model's is not read.
  save_model(back, path);
  std::ofstream(pkl, std::ios::app) << " ";
  EXPECT_THAT(test::error_of([&] { load_model(path, RegressorRegistry::global(), mean_loader(&calls)); }),
              HasSubstr("does not match the model file"));
  EXPECT_EQ(calls, 1);
  // ... nor replaced: it is no longer the one the model file names.
  EXPECT_THAT(test::error_of([&] { save_model(m, path); }), HasSubstr("refusing to replace it"));
  fs::remove(pkl);
  EXPECT_EQ(test::error_of([&] { load_model(path, RegressorRegistry::global(), mean_loader(&calls)); }),
            pkl.string() + ": cannot open for reading: No such file or directory (the pickle of the model " + path.string() + ")");
  fs::create_directory(pkl);
  EXPECT_THAT(test::error_of([&] { load_model(path, RegressorRegistry::global(), mean_loader(&calls)); }),
              HasSubstr(pkl.string() + ": read failed: Is a directory (the pickle of the model"));
  fs::remove(pkl);
  fs::remove(path);
}

TEST(ModelFile, APickleThatIsNotOursIsNeverReplaced) {
  const Matrix x = random_rows(50, 24, 6);
  const Model pickled = Model::train(std::make_unique<MeanPickled>("py_mean", Params()), x, model_labels(x), 3);
  const fs::path path = temp_model("users_pickle"), pkl = pickle_path(path);
  std::ofstream(pkl) << "the user's own pickle";
  EXPECT_THAT(test::error_of([&] { save_model(pickled, path); }), HasSubstr(pkl.string() + ": exists and is not a pickle saved with the dicestack model"));
  EXPECT_FALSE(fs::exists(path));
  // A built-in model beside it leaves the user's file alone...
  const Model knn = Model::train(RegressorRegistry::global().create("knn"), x, model_labels(x), 3);
  save_model(knn, path);
  EXPECT_TRUE(fs::exists(pkl));
  fs::remove(pkl);
  // ... and a built-in model saved over a pickled one removes that model's pickle.
  save_model(pickled, path);
  ASSERT_TRUE(fs::exists(pkl));
  save_model(knn, path);
  EXPECT_FALSE(fs::exists(pkl));
  EXPECT_EQ(load_model(path).regressor().name(), "knn");
  fs::remove(path);
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
              HasSubstr("format version 7 is newer than this dicestack reads (3); upgrade dicestack"));
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
