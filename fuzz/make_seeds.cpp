// Writes the generated part of the seed corpus (scripts/fuzz.sh --make-seeds): for every
// built-in regressor, the payloads of two tiny fitted models (20 rows, 24 -> 3 and 4 -> 2, fixed
// seeds) behind their dimension bytes; a model file of each (and one in format 1); the default
// world config; a 3-step demonstration set's meta.json and episode CSV, as write_demo_set
// writes them. Usage: dicestack_fuzz_seeds CORPUS_DIR
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include <dicestack/core/error.hpp>
#include <dicestack/core/rng.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/regressors/model.hpp>

#include "payload_input.hpp"

namespace {

namespace fs = std::filesystem;
using namespace dicestack;

void write(const fs::path& file, const std::string& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out << bytes;
  if (!out) throw InputError(file.string() + ": cannot write");
  std::printf("%8zu  %s\n", bytes.size(), file.string().c_str());
}

std::string slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// 20 rows of inputs in [-1, 1] and labels that depend on them smoothly, plus a little noise.
void tiny_data(std::size_t d, std::size_t k, std::uint64_t seed, Matrix& x, Matrix& y) {
  Rng rng(seed);
  x.resize(20, static_cast<Eigen::Index>(d));
  y.resize(20, static_cast<Eigen::Index>(k));
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    for (Eigen::Index j = 0; j < x.cols(); ++j) x(i, j) = rng.uniform(-1.0, 1.0);
    for (Eigen::Index j = 0; j < y.cols(); ++j)
      y(i, j) = x(i, j % x.cols()) - 0.5 * x(i, (j + 1) % x.cols()) + 0.05 * rng.uniform(-1.0, 1.0);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: dicestack_fuzz_seeds CORPUS_DIR\n");
    return 2;
  }
  try {
    const fs::path out = argv[1];
    const auto& registry = RegressorRegistry::global();
    for (const auto& name : {"knn", "linear_svr", "rbf_svr", "mlp", "random_forest", "gbt"}) {
      for (const auto& [d, k] : {std::pair<std::size_t, std::size_t>{24, 3}, {4, 2}}) {
        Matrix x, y;
        tiny_data(d, k, 18, x, y);
        auto r = registry.create(name, fuzz::seed_fit_settings(name));
        r->fit(x, y, 18);
        write(out / (std::string("payload_") + name) / ("fit_" + std::to_string(d) + "x" + std::to_string(k)),
              fuzz::dim_bytes(d, k) + r->save_payload());
      }
    }
    // Whole model files: each regressor on 20 states, and a format 1 file (no feature map).
    const fs::path tmp = fs::temp_directory_path() / ("dicestack_fuzz_seeds_" + std::to_string(getpid()));
    fs::create_directories(tmp);
    for (const auto& name : {"knn", "linear_svr", "rbf_svr", "mlp", "random_forest", "gbt"}) {
      Matrix x, y;
      tiny_data(kStateDim, kActionDim, 19, x, y);
      save_model(Model::train(registry.create(name, fuzz::seed_fit_settings(name)), x, y, 19), tmp / "m.dsm");
      write(out / "model_file" / (std::string(name) + ".dsm"), slurp(tmp / "m.dsm"));
    }
    {
      const std::string file = slurp(out / "model_file" / "linear_svr.dsm");
      const auto newline = file.find('\n');
      auto header = nlohmann::json::parse(file.substr(0, newline));
      for (const char* key : {"features", "features_version", "input_dim", "input_names", "checksum"}) header.erase(key);
      header["version"] = 1;
      write(out / "model_file" / "version1.dsm", header.dump() + file.substr(newline));
    }
    write(out / "world_config" / "default.json", to_json(WorldConfig{}));
    WorldConfig arm;
    arm.embodiment = Embodiment::arm;
    write(out / "world_config" / "arm.json", to_json(arm));

    DemoSet set;
    set.description = "fuzz seed";
    Episode e;
    Rng rng(18);
    for (int t = 0; t < 3; ++t) {
      State s{};
      for (double& v : s) v = rng.uniform(-5.0, 5.0);
      e.states.push_back(s);
      e.actions.push_back({rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0)});
      e.sources.push_back(t == 0 ? StepSource::human : StepSource::expert);
    }
    e.outcome.steps = 3;
    set.episodes.push_back(e);
    write_demo_set(set, tmp / "set");
    write(out / "demo_meta" / "written.json", slurp(tmp / "set" / "meta.json"));
    write(out / "episode_csv" / "written.csv", slurp(tmp / "set" / "episode_0000.csv"));
    fs::remove_all(tmp);
  } catch (const std::exception& ex) {
    std::fprintf(stderr, "dicestack_fuzz_seeds: %s\n", ex.what());
    return 1;
  }
  return 0;
}
