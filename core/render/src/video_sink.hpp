#pragma once
// The video writer's interface to its module. OpenCV's video I/O pulls in some 240 shared
// libraries (FFmpeg, GDAL and theirs), so it lives in a module, libdicestack_videoio.so,
// loaded beside the render library only when a video is written, not at every program start.
#include <cstdint>

namespace dicestack {

/// An open video file: frames are added in order, then it is closed.
class VideoSink {
 public:
  virtual ~VideoSink() = default;
  /// One frame of the size the sink was opened with, BGR, 8 bits per channel.
  virtual void add(const std::uint8_t* bgr) = 0;
  virtual void close() = 0;
};

}  // namespace dicestack

/// The module's one entry: a sink writing `path` (MPEG-4 when `mp4`, else Motion JPEG) at
/// `fps` frames per second, or null when the format cannot be written here. The caller deletes it.
extern "C" dicestack::VideoSink* dicestack_open_video(const char* path, int mp4, double fps, int width, int height);
/// The name the render library looks the entry up by.
inline constexpr const char* kOpenVideoSymbol = "dicestack_open_video";
/// The module's file name, beside the render library.
inline constexpr const char* kVideoModuleFile = "libdicestack_videoio.so";
