#pragma once
// Animated GIF output for write_frames (giflib: OpenCV 4.6 writes no GIF). Private to core/render:
// giflib stays behind it.
#include <filesystem>
#include <vector>

#include <dicestack/core/render.hpp>

struct GifFileType;

namespace dicestack {

/// Writes frames of one size into a looping GIF. Colours map to a fixed 6 x 7 x 6 cube: the
/// renders are flat colours, and a fixed palette keeps the output deterministic. Frames after
/// the first store only what changed. Throws InputError naming the file on any failure.
class GifWriter {
 public:
  GifWriter(const std::filesystem::path& path, int width, int height);
  ~GifWriter();
  GifWriter(const GifWriter&) = delete;
  GifWriter& operator=(const GifWriter&) = delete;

  /// Appends a frame shown for `centiseconds`.
  void add(const Image& frame, int centiseconds);
  /// Finishes the file; the destructor closes an unfinished one without reporting.
  void close();

 private:
  void check(int status, const char* what) const;

  std::filesystem::path path_;
  GifFileType* gif_ = nullptr;
  int width_, height_;
  std::vector<unsigned char> previous_;  ///< the last frame's palette indices (empty before the first)
};

}  // namespace dicestack
