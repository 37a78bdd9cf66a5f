#include "gif_writer.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <vector>

#include <fcntl.h>
#include <gif_lib.h>
#include <unistd.h>

#include <dicestack/core/error.hpp>

namespace dicestack {
namespace {

constexpr int kR = 6, kG = 7, kB = 6;  // 252 colours
constexpr GifPixelType kUnchanged = 255;  // transparent: the pixel of the frame before shows through

int level(std::uint8_t v, int levels) { return (v * (levels - 1) + 127) / 255; }

}  // namespace

GifWriter::GifWriter(const std::filesystem::path& path, int width, int height) : path_(path), width_(width), height_(height) {
  // Opened here rather than by giflib, which creates files readable by their owner only.
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw InputError(path.string() + ": cannot write a GIF (" + std::strerror(errno) + ")");
  int error = 0;
  gif_ = EGifOpenFileHandle(fd, &error);
  if (!gif_) {
    ::close(fd);
    throw InputError(path.string() + ": cannot write a GIF (" + GifErrorString(error) + ")");
  }
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
  // Each frame after the first holds only the box where pixels changed, the unchanged ones in
  // it transparent: the scene is mostly still, and long runs of one index compress well.
  const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  std::vector<GifPixelType> now(n);
  const std::uint8_t* px = frame.bgr.data();
  for (std::size_t i = 0; i < n; ++i, px += 3)
    now[i] = static_cast<GifPixelType>((level(px[2], kR) * kG + level(px[1], kG)) * kB + level(px[0], kB));
  int left = 0, top = 0, right = width_ - 1, bottom = height_ - 1;
  const bool first = previous_.empty();
  if (!first) {
    left = width_, top = height_, right = -1, bottom = -1;
    for (int y = 0; y < height_; ++y)
      for (int x = 0; x < width_; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
        if (now[i] == previous_[i]) continue;
        left = std::min(left, x), right = std::max(right, x), top = std::min(top, y), bottom = std::max(bottom, y);
      }
    if (right < 0) left = right = top = bottom = 0;  // nothing changed: one transparent pixel
  }
  GraphicsControlBlock gcb{DISPOSE_DO_NOT, false, std::max(centiseconds, 1), first ? NO_TRANSPARENT_COLOR : kUnchanged};
  GifByteType extension[4];
  EGifGCBToExtension(&gcb, extension);
  check(EGifPutExtension(gif_, GRAPHICS_EXT_FUNC_CODE, 4, extension), "frame delay");
  const int w = right - left + 1, h = bottom - top + 1;
  check(EGifPutImageDesc(gif_, left, top, w, h, false, nullptr), "frame");
  std::vector<GifPixelType> line(static_cast<std::size_t>(w));
  for (int y = top; y <= bottom; ++y) {
    for (int x = left; x <= right; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
      line[static_cast<std::size_t>(x - left)] = first || now[i] != previous_[i] ? now[i] : kUnchanged;
    }
    check(EGifPutLine(gif_, line.data(), w), "pixels");
  }
  previous_ = std::move(now);
}

void GifWriter::close() {
  int error = 0;
  GifFileType* gif = gif_;
  gif_ = nullptr;
  if (EGifCloseFile(gif, &error) != GIF_OK) throw InputError(path_.string() + ": closing the GIF failed (" + GifErrorString(error) + ")");
}

}  // namespace dicestack
