#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/render.hpp>

#include <dicestack/test/helpers.hpp>

namespace dicestack {
namespace {

TEST(Render, DrawsTheOriginalWindowWithShapes) {
  const WorldConfig c;
  const Image img = render_state(paper_start_state(c), c, {12, {}, "test"});
  EXPECT_EQ(img.width, 900);
  EXPECT_EQ(img.height, 700);
  ASSERT_EQ(img.bgr.size(), 900u * 700u * 3u);
  // The cup's base (mouth down at the start) crosses x = 450 px at y = 3.37 m; it is drawn
  // in the cup colour, not the background.
  const std::size_t row = static_cast<std::size_t>(700 - 337), col = 450;
  const std::uint8_t* px = &img.bgr[(row * 900 + col) * 3];
  EXPECT_NE(px[0], px[2]) << "expected the orange cup at (450, 363)";
}

TEST(Render, WritesAPngAtomically) {
  const WorldConfig c;
  const auto path = test::scratch_path("dicestack_render_test.png");
  std::filesystem::remove(path);
  write_png(render_state(paper_start_state(c), c, {}), path);
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path.string() + ".tmp"));
  std::ifstream in(path, std::ios::binary);
  char magic[4]{};
  in.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace dicestack
