#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <gif_lib.h>
#include <sys/stat.h>
#include <zlib.h>

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

// Reads back what write_png wrote, chunk by chunk: each CRC, the header, and the pixels.
std::vector<std::uint8_t> png_pixels_as_bgr(const std::string& bytes, int& width, int& height) {
  const auto u32 = [&](std::size_t at) {
    return (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at])) << 24) |
           (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + 1])) << 16) |
           (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + 2])) << 8) |
           static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at + 3]));
  };
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::string idat;
  for (std::size_t at = 8; at + 12 <= bytes.size();) {
    const std::uint32_t length = u32(at);
    const std::string type = bytes.substr(at + 4, 4);
    const auto* typed = reinterpret_cast<const Bytef*>(bytes.data() + at + 4);
    EXPECT_EQ(crc32(crc32(0L, Z_NULL, 0), typed, length + 4), u32(at + 8 + length)) << type;
    if (type == "IHDR") {
      width = static_cast<int>(u32(at + 8));
      height = static_cast<int>(u32(at + 12));
      EXPECT_EQ(bytes.substr(at + 16, 5), std::string("\x08\x02\0\0\0", 5)) << "8-bit RGB, not interlaced";
    }
    if (type == "IDAT") idat += bytes.substr(at + 8, length);
    at += 12 + length;
  }
  const auto w = static_cast<std::size_t>(width), h = static_cast<std::size_t>(height);
  std::vector<std::uint8_t> raw(h * (1 + 3 * w));
  uLongf size = raw.size();
  EXPECT_EQ(uncompress(raw.data(), &size, reinterpret_cast<const Bytef*>(idat.data()), idat.size()), Z_OK);
  EXPECT_EQ(size, raw.size());
  std::vector<std::uint8_t> bgr;
  for (std::size_t y = 0; y < h; ++y) {
    EXPECT_EQ(raw[y * (1 + 3 * w)], 0) << "row " << y << ": no filter";
    for (std::size_t x = 0; x < w; ++x) {
      const std::uint8_t* rgb = &raw[y * (1 + 3 * w) + 1 + 3 * x];
      bgr.insert(bgr.end(), {rgb[2], rgb[1], rgb[0]});
    }
  }
  return bgr;
}

TEST(Render, APngHoldsTheImagesPixelsExactly) {
  const WorldConfig c;
  const Image img = render_state(paper_start_state(c), c, {3, {}, "png"});
  const auto path = test::scratch_path("dicestack_render_pixels.png");
  write_png(img, path);
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  int width = 0, height = 0;
  const auto pixels = png_pixels_as_bgr(bytes, width, height);
  EXPECT_EQ(width, img.width);
  EXPECT_EQ(height, img.height);
  EXPECT_TRUE(pixels == img.bgr) << "the decoded pixels differ from the image drawn";
  Image odd{3, 2, {}};
  odd.bgr.resize(17);
  EXPECT_THAT(test::error_of([&] { write_png(odd, path); }), ::testing::HasSubstr("3 x 2 pixels holds 17 bytes"));
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
