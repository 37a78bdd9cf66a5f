#include "gif_writer.hpp"

#include <algorithm>
#include <vector>

#include <gif_lib.h>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

constexpr int kR = 6, kG = 7, kB = 6;  // 252 colours

int level(std::uint8_t v, int levels) { return (v * (levels - 1) + 127) / 255; }

}  // namespace

GifWriter::GifWriter(const std::filesystem::path& path, int width, int height) : path_(path), width_(width), height_(height) {
  int error = 0;
  gif_ = EGifOpenFileName(path.c_str(), false, &error);
  if (!gif_) throw InputError(path.string() + ": cannot write a GIF (" + GifErrorString(error) + ")");
  std::vector<GifColorType> colours(256, GifColorType{0, 0, 0});
  for (int r = 0; r < kR; ++r)
    for (int g = 0; g < kG; ++g)
      for (int b = 0; b < kB; ++b)
        colours[static_cast<std::size_t>((r * kG + g) * kB + b)] = {static_cast<GifByteType>(r * 255 / (kR - 1)),
                                                                     static_cast<GifByteType>(g * 255 / (kG - 1)),
                                                                     static_cast<GifByteType>(b * 255 / (kB - 1))};
  ColorMapObject* map = GifMakeMapObject(256, colours.data());
  EGifSetGifVersion(gif_, true);
  const int status = EGifPutScreenDesc(gif_, width, height, 8, 0, map);
  GifFreeMapObject(map);
  check(status, "screen");
  // Loop forever (the Netscape application extension).
  static const GifByteType netscape[] = "NETSCAPE2.0";
  static const GifByteType loop[] = {1, 0, 0};
  check(EGifPutExtensionLeader(gif_, APPLICATION_EXT_FUNC_CODE), "loop");
  check(EGifPutExtensionBlock(gif_, 11, netscape), "loop");
  check(EGifPutExtensionBlock(gif_, 3, loop), "loop");
  check(EGifPutExtensionTrailer(gif_), "loop");
}

GifWriter::~GifWriter() {
  if (gif_) EGifCloseFile(gif_, nullptr);
}

void GifWriter::check(int status, const char* what) const {
  if (status != GIF_OK) throw InputError(path_.string() + ": writing the GIF failed at the " + what + " (" + GifErrorString(gif_ ? gif_->Error : 0) + ")");
}

void GifWriter::add(const Image& frame, int centiseconds) {
  if (frame.width != width_ || frame.height != height_)
    throw InputError(path_.string() + ": frame of " + std::to_string(frame.width) + " x " + std::to_string(frame.height) +
                     ", expected " + std::to_string(width_) + " x " + std::to_string(height_));
  GraphicsControlBlock gcb{DISPOSE_DO_NOT, false, std::max(centiseconds, 1), NO_TRANSPARENT_COLOR};
  GifByteType extension[4];
  EGifGCBToExtension(&gcb, extension);
  check(EGifPutExtension(gif_, GRAPHICS_EXT_FUNC_CODE, 4, extension), "frame delay");
  check(EGifPutImageDesc(gif_, 0, 0, width_, height_, false, nullptr), "frame");
  std::vector<GifPixelType> line(static_cast<std::size_t>(width_));
  for (int y = 0; y < height_; ++y) {
    const std::uint8_t* px = frame.bgr.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) * 3;
    for (int x = 0; x < width_; ++x, px += 3)
      line[static_cast<std::size_t>(x)] = static_cast<GifPixelType>((level(px[2], kR) * kG + level(px[1], kG)) * kB + level(px[0], kB));
    check(EGifPutLine(gif_, line.data(), width_), "pixels");
  }
}

void GifWriter::close() {
  int error = 0;
  GifFileType* gif = gif_;
  gif_ = nullptr;
  if (EGifCloseFile(gif, &error) != GIF_OK) throw InputError(path_.string() + ": closing the GIF failed (" + GifErrorString(error) + ")");
}

}  // namespace dicestack
