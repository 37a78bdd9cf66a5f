// libdicestack_videoio.so: the one user of OpenCV's video I/O, loaded by video.cpp when a
// video is written (video_sink.hpp says why it is a module).
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "video_sink.hpp"

namespace {

class OpenCvVideo final : public dicestack::VideoSink {
 public:
  OpenCvVideo(const char* path, int fourcc, double fps, int width, int height)
      : width_(width), height_(height), video_(path, cv::CAP_FFMPEG, fourcc, fps, cv::Size(width, height)) {}
  bool is_open() const { return video_.isOpened(); }
  void add(const std::uint8_t* bgr) override {
    video_.write(cv::Mat(height_, width_, CV_8UC3, const_cast<std::uint8_t*>(bgr)));
  }
  void close() override { video_.release(); }

 private:
  int width_, height_;
  cv::VideoWriter video_;
};

}  // namespace

extern "C" __attribute__((visibility("default"))) dicestack::VideoSink* dicestack_open_video(const char* path, int mp4,
                                                                                              double fps, int width,
                                                                                              int height) {
  try {
    const int fourcc = mp4 ? cv::VideoWriter::fourcc('m', 'p', '4', 'v') : cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
    auto* video = new OpenCvVideo(path, fourcc, fps, width, height);
    if (video->is_open()) return video;
    delete video;
  } catch (const cv::Exception&) {
  }
  return nullptr;
}
