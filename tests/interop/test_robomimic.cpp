// robomimic HDF5: export -> import round trips, and bad files refused naming the path inside the
// file.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <hdf5.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <dicestack/datasets/demo_set.hpp>
#include <dicestack/interop/interop.hpp>

#include <dicestack/test/helpers.hpp>
#include <dicestack/test/interop.hpp>

namespace dicestack {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::expect_same;
using test::replace_f64;
using test::scratch;
using test::small_set;
using test::through_folder;

TEST(Robomimic, ExportThenImportIsExact) {
  const DemoSet set = through_folder(small_set(), "small");
  const fs::path file = scratch("small.hdf5");
  export_robomimic(set, file);
  expect_same(set, import_robomimic(file));
  // Through our folder format again: still the same.
  expect_same(set, through_folder(import_robomimic(file), "small_back"));
  export_robomimic(set, file);  // our own export is replaced
}

// ---- bad files: edited copies of a good export --------------------------------------------------

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

}  // namespace
}  // namespace dicestack
