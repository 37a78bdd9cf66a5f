#pragma once
// What the interop suite's files share: a scratch folder removed when the tests end, the small
// set every round trip starts from, and a dataset of an HDF5 file replaced (include only in
// dicestack_interop_tests).
#include <gtest/gtest.h>

#include <hdf5.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <dicestack/core/types.hpp>
#include <dicestack/core/world_config.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/episodes.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack::test {

/// The source tree (tests/datasets/data, data/cupdice).
inline const std::filesystem::path kSource = std::filesystem::path(DICESTACK_SOURCE_DIR);

/// This process's scratch folder: temp/dicestack_interop_<pid>.
inline std::filesystem::path scratch_root() {
  return std::filesystem::temp_directory_path() / ("dicestack_interop_" + std::to_string(getpid()));
}

/// `name` in the scratch folder, which is made if missing.
inline std::filesystem::path scratch(const std::string& name) {
  std::filesystem::create_directories(scratch_root());
  return scratch_root() / name;
}

/// Each test process removes its scratch folder at the end.
struct RemoveScratch : ::testing::Environment {
  void TearDown() override { std::filesystem::remove_all(scratch_root()); }
};
inline const auto* const kRemoveScratch = ::testing::AddGlobalTestEnvironment(new RemoveScratch);

/// The small set of tests/datasets/data/good (hand-made, format v1: given transitions here) and a
/// few recorded episodes of the scripted expert (a time limit and, if any, a success).
inline DemoSet small_set() {
  DemoSet set = read_demo_set(kSource / "tests" / "datasets" / "data" / "good");
  for (auto& e : set.episodes) {
    State last = e.states.back();
    last[state_index::kCupX] += 0.1 + 0.2;
    e.final_state = last;
    for (std::size_t t = 0; t < e.size(); ++t) e.rewards.push_back(-1.0 / 3.0 * static_cast<double>(t + 1));
    e.truncated = true;
  }
  WorldConfig w = set.world;
  w.episode.max_steps = 40;
  for (auto e : record_expert("scripted", {}, w, record_request(4, 3, 1))) {
    e.name = "recorded_" + std::to_string(set.episodes.size());
    set.episodes.push_back(std::move(e));
  }
  set.episodes[1].sources[1] = StepSource::correction;
  set.episodes[2].seed = 18446744073709551615ull;  // the largest seed survives
  return set;
}

/// Two sets alike in their world, description, provenance and every episode.
inline void expect_same(const DemoSet& a, const DemoSet& b) {
  EXPECT_EQ(to_json(a.world), to_json(b.world));
  EXPECT_EQ(a.description, b.description);
  EXPECT_EQ(a.provenance, b.provenance);
  ASSERT_EQ(a.episodes.size(), b.episodes.size());
  for (std::size_t i = 0; i < a.episodes.size(); ++i) {
    expect_same_episode(a.episodes[i], b.episodes[i]);
  }
}

/// What our own folder format gives back: the reference a round trip must equal.
inline DemoSet through_folder(const DemoSet& set, const std::string& name) {
  const std::filesystem::path dir = scratch(name);
  write_demo_set(set, dir);
  return read_demo_set(dir);
}

/// Replaces the dataset at `path` in the open file `f` by float64s of shape `dims`, all `fill`.
inline void replace_f64(hid_t f, const char* path, std::vector<hsize_t> dims, double fill) {
  H5Ldelete(f, path, H5P_DEFAULT);
  hsize_t n = 1;
  for (auto d : dims) n *= d;
  std::vector<double> v(n, fill);
  const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t ds = H5Dcreate2(f, path, H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Dclose(ds);
  H5Sclose(space);
}

}  // namespace dicestack::test
