#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <gif_lib.h>
#include <sys/stat.h>

#include <dicestack/core/env.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/judge.hpp>
#include <dicestack/core/render.hpp>
#include <dicestack/core/video.hpp>
#include <dicestack/core/world.hpp>

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

// Frames after the first store only the box that changed, its unchanged pixels transparent:
// decoded and laid over each other they must give every frame as drawn (in the GIF's colours),
// and the file is readable by others as every output is.
TEST(Render, GifFramesStoreOnlyChangesYetDecodeToEveryFrame) {
  const WorldConfig c;
  DiceEnv env(c);
  std::vector<State> states{env.reset_to(random_start_state(c, 3), 3)};
  for (int t = 0; t < 12; ++t) states.push_back(env.step({t < 6 ? 1.0 : 0.0, 0.5, 0.0}).observation);
  states.push_back(states.back());  // a frame that changes nothing
  const auto path = test::scratch_path("dicestack_render_delta.gif");
  FrameOptions options;
  options.render.pixels_per_metre = 40;
  options.every = 2;
  write_frames(states, c, "delta", path, options);
  struct stat st{};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0044, 0044) << "readable by group and others, as the umask allows";

  int error = 0;
  GifFileType* gif = DGifOpenFileName(path.c_str(), &error);
  ASSERT_NE(gif, nullptr);
  ASSERT_EQ(DGifSlurp(gif), GIF_OK);
  const std::size_t frames = (states.size() + 1) / 2;
  ASSERT_EQ(static_cast<std::size_t>(gif->ImageCount), frames);
  const int w = gif->SWidth, h = gif->SHeight;
  const ColorMapObject* map = gif->SColorMap;
  std::vector<GifByteType> canvas(static_cast<std::size_t>(w * h), 0);
  Outcome outcome;
  World probe(c);
  std::size_t smaller = 0;
  for (std::size_t f = 0; f < frames; ++f) {
    const SavedImage& image = gif->SavedImages[f];
    GraphicsControlBlock gcb;
    ASSERT_EQ(DGifSavedExtensionToGCB(gif, static_cast<int>(f), &gcb), GIF_OK);
    const GifImageDesc& d = image.ImageDesc;
    smaller += d.Width * d.Height < w * h;
    for (int y = 0; y < d.Height; ++y)
      for (int x = 0; x < d.Width; ++x) {
        const GifByteType v = image.RasterBits[y * d.Width + x];
        if (v != gcb.TransparentColor) canvas[static_cast<std::size_t>((d.Top + y) * w + d.Left + x)] = v;
      }
    // The frame as drawn: state 2f with the judge's outcome so far.
    for (std::size_t t = f == 0 ? 0 : 2 * f - 1; t <= 2 * f; ++t)
      if (t > 0) {
        probe.set_state(states[t]);
        observe(outcome, states[t], probe.touching_walls(), c);
      }
    const Image drawn = render_state(states[2 * f], c, {static_cast<int>(2 * f), outcome, "delta"}, options.render);
    ASSERT_EQ(drawn.width, w);
    int off = 0;
    for (int i = 0; i < w * h; ++i) {
      const GifColorType colour = map->Colors[canvas[static_cast<std::size_t>(i)]];
      const std::uint8_t* px = &drawn.bgr[static_cast<std::size_t>(i) * 3];
      off += std::abs(colour.Red - px[2]) > 26 || std::abs(colour.Green - px[1]) > 22 || std::abs(colour.Blue - px[0]) > 26;
    }
    EXPECT_EQ(off, 0) << "frame " << f << ": pixels farther from the drawing than a palette step";
  }
  EXPECT_GE(smaller, frames - 2) << "frames after the first hold only what changed";
  DGifCloseFile(gif, &error);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace dicestack
