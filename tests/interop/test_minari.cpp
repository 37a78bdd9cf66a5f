// Minari datasets: export -> import round trips, and bad datasets refused naming the file and
// the path inside it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <hdf5.h>

#include <filesystem>
#include <functional>
#include <string>

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

// ---- bad files: edited copies of a good export --------------------------------------------------

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
