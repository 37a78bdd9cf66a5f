// robomimic and Minari HDF5: export -> import round trips, the human recordings, and bad files
// refused naming the path inside the file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <hdf5.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <dicestack/core/error.hpp>
#include <dicestack/datasets/cupdice_import.hpp>
#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/datasets/replay.hpp>
#include <dicestack/interop/interop.hpp>
#include <dicestack/learners/record.hpp>

#include <dicestack/test/episodes.hpp>
#include <dicestack/test/helpers.hpp>
#include <dicestack/test/requests.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

const fs::path kSource = fs::path(DICESTACK_SOURCE_DIR);

fs::path scratch_root() { return fs::temp_directory_path() / ("dicestack_interop_" + std::to_string(getpid())); }

fs::path scratch(const std::string& name) {
  fs::create_directories(scratch_root());
  return scratch_root() / name;
}

// Each test process removes its scratch folder at the end.
struct RemoveScratch : ::testing::Environment {
  void TearDown() override { fs::remove_all(scratch_root()); }
};
const auto* const kRemoveScratch = ::testing::AddGlobalTestEnvironment(new RemoveScratch);

// The small set of tests/datasets/data/good (hand-made, format v1: given transitions here) and a
// few recorded episodes of the scripted expert (a time limit and, if any, a success).
DemoSet small_set() {
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
  for (auto e : record_expert("scripted", {}, w, test::record_request(4, 3, 1))) {
    e.name = "recorded_" + std::to_string(set.episodes.size());
    set.episodes.push_back(std::move(e));
  }
  set.episodes[1].sources[1] = StepSource::correction;
  set.episodes[2].seed = 18446744073709551615ull;  // the largest seed survives
  return set;
}

void expect_same(const DemoSet& a, const DemoSet& b) {
  EXPECT_EQ(to_json(a.world), to_json(b.world));
  EXPECT_EQ(a.description, b.description);
  EXPECT_EQ(a.provenance, b.provenance);
  ASSERT_EQ(a.episodes.size(), b.episodes.size());
  for (std::size_t i = 0; i < a.episodes.size(); ++i) {
    test::expect_same_episode(a.episodes[i], b.episodes[i]);
  }
}

// What our own folder format gives back: the reference a round trip must equal.
DemoSet through_folder(const DemoSet& set, const std::string& name) {
  const fs::path dir = scratch(name);
  write_demo_set(set, dir);
  return read_demo_set(dir);
}

TEST(Robomimic, ExportThenImportIsExact) {
  const DemoSet set = through_folder(small_set(), "small");
  const fs::path file = scratch("small.hdf5");
  export_robomimic(set, file);
  expect_same(set, import_robomimic(file));
  // Through our folder format again: still the same.
  expect_same(set, through_folder(import_robomimic(file), "small_back"));
  export_robomimic(set, file);  // our own export is replaced
}

TEST(Minari, ExportThenImportIsExact) {
  const DemoSet set = through_folder(small_set(), "small_m");
  const fs::path dir = scratch("small_minari");
  export_minari(set, dir, "dicestack/small-v0");
  EXPECT_TRUE(fs::exists(dir / "data" / "main_data.hdf5"));
  EXPECT_TRUE(fs::exists(dir / "data" / "metadata.json"));
  expect_same(set, import_minari(dir));
  export_minari(set, dir, "dicestack/small-v0");  // our own export is replaced
  expect_same(set, import_minari(dir));
}

TEST(Interop, TheHumanRecordingsExportAndReimport) {
  const DemoSet set = through_folder(import_cupdice(kSource / "data" / "cupdice", WorldConfig{}), "human");
  ASSERT_EQ(set.episodes.size(), 68u);
  const fs::path file = scratch("human.hdf5"), dir = scratch("human_minari");
  export_robomimic(set, file);
  expect_same(set, import_robomimic(file));
  export_minari(set, dir, default_minari_dataset_id(dir));
  expect_same(set, import_minari(dir));
}

TEST(Interop, EpisodesWithoutTransitionsAreNamed) {
  DemoSet set = read_demo_set(kSource / "tests" / "datasets" / "data" / "good");
  EXPECT_THAT(recover_transitions(set.episodes, set.world), (std::vector<std::string>{"episode_0000", "episode_0001"}));
  const auto message = test::error_of([&] { export_robomimic(set, scratch("none.hdf5")); });
  EXPECT_THAT(message, HasSubstr("2 of 2 episodes have no final state"));
  EXPECT_THAT(message, HasSubstr("episode_0000, episode_0001"));
  EXPECT_FALSE(fs::exists(scratch("none.hdf5")));
}

TEST(Interop, AUsersFilesAreNeverReplaced) {
  const DemoSet set = through_folder(small_set(), "owner");
  const fs::path file = scratch("user.hdf5");
  std::ofstream(file) << "a user's notes\n";
  EXPECT_THAT(test::error_of([&] { export_robomimic(set, file); }), HasSubstr("exists and is not a dicestack robomimic export"));
  const fs::path dir = scratch("user_folder");
  fs::create_directories(dir / "data");
  std::ofstream(dir / "data" / "notes.txt") << "mine\n";
  EXPECT_THAT(test::error_of([&] { export_minari(set, dir, "dicestack/x-v0"); }),
              HasSubstr("exists and is not a dicestack Minari export (it holds data/notes.txt)"));
  EXPECT_TRUE(fs::exists(dir / "data" / "notes.txt"));
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "a user's notes");
}

// ---- bad files: edited copies of a good export --------------------------------------------------

void replace_f64(hid_t f, const char* path, std::vector<hsize_t> dims, double fill) {
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

void poke(hid_t f, const char* path, std::size_t index, double value) {
  const hid_t ds = H5Dopen2(f, path, H5P_DEFAULT);
  const hid_t space = H5Dget_space(ds);
  std::vector<double> v(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  v[index] = value;
  H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
  H5Sclose(space);
  H5Dclose(ds);
}


class BadRobomimic : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    good_ = new fs::path(scratch("good.hdf5"));
    export_robomimic(through_folder(small_set(), "bad_base"), *good_);
  }
  static void TearDownTestSuite() { delete good_; }

  // A copy of the good file edited by `edit` (given the open file), and the import's error.
  template <class F>
  std::string import_error(const std::string& name, F&& edit) {
    const fs::path file = scratch(name + ".hdf5");
    fs::copy_file(*good_, file, fs::copy_options::overwrite_existing);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    EXPECT_GE(f, 0);
    edit(f);
    H5Fclose(f);
    return test::error_of([&] { import_robomimic(file); });
  }

  static fs::path* good_;
};
fs::path* BadRobomimic::good_ = nullptr;

TEST_F(BadRobomimic, MissingGroupsDatasetsAndAttributes) {
  EXPECT_THAT(import_error("no_data", [](hid_t f) { H5Ldelete(f, "data", H5P_DEFAULT); }), HasSubstr(".hdf5: data: missing"));
  EXPECT_THAT(import_error("no_actions", [](hid_t f) { H5Ldelete(f, "data/demo_1/actions", H5P_DEFAULT); }),
              HasSubstr(": data/demo_1/actions: missing"));
  EXPECT_THAT(import_error("no_obs", [](hid_t f) { H5Ldelete(f, "data/demo_2/obs", H5P_DEFAULT); }),
              HasSubstr(": data/demo_2/obs/cup_pose: missing"));
  EXPECT_THAT(import_error("no_next", [](hid_t f) { H5Ldelete(f, "data/demo_0/next_obs/die2_vel", H5P_DEFAULT); }),
              HasSubstr(": data/demo_0/next_obs/die2_vel: missing"));
  EXPECT_THAT(import_error("no_env", [](hid_t f) {
                const hid_t g = H5Gopen2(f, "data", H5P_DEFAULT);
                H5Adelete(g, "env_args");
                H5Gclose(g);
              }),
              HasSubstr(": data: attribute env_args is missing"));
  EXPECT_THAT(import_error("no_samples", [](hid_t f) {
                const hid_t g = H5Gopen2(f, "data/demo_3", H5P_DEFAULT);
                H5Adelete(g, "num_samples");
                H5Gclose(g);
              }),
              HasSubstr(": data/demo_3: attribute num_samples is missing"));
  EXPECT_THAT(import_error("stranger", [](hid_t f) { H5Gclose(H5Gcreate2(f, "data/notes", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)); }),
              HasSubstr(": data/notes: not a demo_<n> group"));
}

TEST_F(BadRobomimic, WrongShapesDtypesAndValues) {
  EXPECT_THAT(import_error("short_states", [](hid_t f) { replace_f64(f, "data/demo_0/states", {3, 24}, 0.0); }),
              HasSubstr(": data/demo_0/states: shape (3, 24), expected (4, 24)"));
  EXPECT_THAT(import_error("flat_actions", [](hid_t f) { replace_f64(f, "data/demo_1/actions", {9}, 0.0); }),
              HasSubstr(": data/demo_1/actions: shape (9,), expected (T, 3) with T >= 1"));
  EXPECT_THAT(import_error("nan_action", [](hid_t f) { poke(f, "data/demo_1/actions", 4, std::nan("")); }),
              HasSubstr(": data/demo_1/actions: row 1 column 1 is NaN; values must be finite"));
  EXPECT_THAT(import_error("inf_reward", [](hid_t f) { poke(f, "data/demo_2/rewards", 0, HUGE_VAL); }),
              HasSubstr(": data/demo_2/rewards: item 0 is infinite"));
  EXPECT_THAT(import_error("big_action", [](hid_t f) { poke(f, "data/demo_0/actions", 2, 1.5); }),
              HasSubstr(": data/demo_0/actions: row 0 column 2 is outside [-1, 1]"));
  EXPECT_THAT(import_error("obs_edit", [](hid_t f) { poke(f, "data/demo_3/obs/die1_pose", 4, 9.0); }),
              HasSubstr(": data/demo_3/obs/die1_pose: row 1 column 1 disagrees with data/demo_3/states"));
  EXPECT_THAT(import_error("string_rewards", [](hid_t f) {
                H5Ldelete(f, "data/demo_0/rewards", H5P_DEFAULT);
                const hid_t t = H5Tcopy(H5T_C_S1);
                H5Tset_size(t, 4);
                const hsize_t n = 4;
                const hid_t space = H5Screate_simple(1, &n, nullptr);
                const hid_t ds = H5Dcreate2(f, "data/demo_0/rewards", t, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
                H5Dwrite(ds, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, "abcdefghijklmnop");
                H5Dclose(ds);
                H5Sclose(space);
                H5Tclose(t);
              }),
              HasSubstr(": data/demo_0/rewards: holds strings, expected floating point numbers"));
  EXPECT_THAT(import_error("group_for_dataset", [](hid_t f) {
                H5Ldelete(f, "data/demo_0/dones", H5P_DEFAULT);
                H5Gclose(H5Gcreate2(f, "data/demo_0/dones", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT));
              }),
              HasSubstr(": data/demo_0/dones: is a group, expected a dataset"));
  EXPECT_THAT(import_error("dones_two", [](hid_t f) { replace_f64(f, "data/demo_0/dones", {4}, 2.0); }),
              HasSubstr(": data/demo_0/dones: item 0 is neither 0 nor 1"));
}

TEST_F(BadRobomimic, NotHdf5AndAnotherEnvironment) {
  const fs::path text = scratch("text.hdf5");
  std::ofstream(text) << "not hdf5\n";
  EXPECT_THAT(test::error_of([&] { import_robomimic(text); }), HasSubstr("text.hdf5: not an HDF5 file"));
  const fs::path absent = scratch("absent.hdf5"), folder = scratch("folder.hdf5");
  EXPECT_EQ(test::error_of([&] { import_robomimic(absent); }), absent.string() + ": cannot open for reading: No such file or directory");
  fs::create_directories(folder);
  EXPECT_EQ(test::error_of([&] { import_robomimic(folder); }), folder.string() + ": read failed: Is a directory");
  fs::permissions(text, fs::perms::none);
  const auto denied = test::unprivileged([&] { return test::error_of([&] { import_robomimic(text); }); });
  if (denied) {
    EXPECT_EQ(*denied, text.string() + ": cannot open for reading: Permission denied") << "not \"not an HDF5 file\"";
  }
  EXPECT_THAT(import_error("lift", [](hid_t f) {
                const hid_t g = H5Gopen2(f, "data", H5P_DEFAULT);
                H5Adelete(g, "env_args");
                const hid_t t = H5Tcopy(H5T_C_S1);
                H5Tset_size(t, H5T_VARIABLE);
                const hid_t space = H5Screate(H5S_SCALAR);
                const hid_t a = H5Acreate2(g, "env_args", t, space, H5P_DEFAULT, H5P_DEFAULT);
                const char* lift = R"({"env_name": "Lift", "type": 1, "env_kwargs": {}})";
                H5Awrite(a, t, &lift);
                H5Aclose(a);
                H5Sclose(space);
                H5Tclose(t);
                H5Gclose(g);
              }),
              HasSubstr(": data attribute env_args: env_name \"Lift\" is not dicestack/DiceStack-v0"));
}

TEST(BadMinari, MissingAndWrongFieldsAreNamed) {
  const DemoSet set = through_folder(small_set(), "bad_minari_base");
  const fs::path good = scratch("bad_minari_good");
  export_minari(set, good, "dicestack/bad-v0");
  auto edited = [&](const std::string& name, const std::function<void(const fs::path&)>& edit) {
    const fs::path dir = scratch(name);
    fs::remove_all(dir);
    fs::copy(good, dir, fs::copy_options::recursive);
    edit(dir);
    return test::error_of([&] { import_minari(dir); });
  };
  auto h5edit = [](const std::function<void(hid_t)>& edit) {
    return [edit](const fs::path& dir) {
      H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
      const hid_t f = H5Fopen((dir / "data" / "main_data.hdf5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
      edit(f);
      H5Fclose(f);
    };
  };
  EXPECT_THAT(edited("m_no_meta", [](const fs::path& d) { fs::remove(d / "data" / "metadata.json"); }),
              HasSubstr("data/metadata.json: missing; not a Minari dataset"));
  EXPECT_EQ(edited("m_meta_folder",
                   [](const fs::path& d) {
                     fs::remove(d / "data" / "metadata.json");
                     fs::create_directory(d / "data" / "metadata.json");
                   }),
            (scratch("m_meta_folder") / "data" / "metadata.json").string() + ": read failed: Is a directory");
  EXPECT_EQ(edited("m_main_folder",
                   [](const fs::path& d) {
                     fs::remove(d / "data" / "main_data.hdf5");
                     fs::create_directory(d / "data" / "main_data.hdf5");
                   }),
            (scratch("m_main_folder") / "data" / "main_data.hdf5").string() + ": read failed: Is a directory");
  EXPECT_THAT(edited("m_no_obs", h5edit([](hid_t f) { H5Ldelete(f, "episode_2/observations", H5P_DEFAULT); })),
              HasSubstr("main_data.hdf5: episode_2/observations: missing"));
  EXPECT_THAT(edited("m_short_obs", h5edit([](hid_t f) { replace_f64(f, "episode_0/observations", {4, 24}, 0.0); })),
              HasSubstr("main_data.hdf5: episode_0/observations: shape (4, 24), expected (5, 24)"));
  EXPECT_THAT(edited("m_gap", h5edit([](hid_t f) { H5Ldelete(f, "episode_1", H5P_DEFAULT); })),
              HasSubstr("\"total_episodes\" is 6, but"));
}

}  // namespace
}  // namespace dicestack
