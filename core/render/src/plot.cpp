// The paper's Fig. 2: a trajectory's cup and dice coordinates as stacked panels over time.
#include <dicestack/core/render.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace dicestack {

namespace si = state_index;

Image render_plot(const std::vector<State>& states, const WorldConfig& world, const std::string& title) {
  struct Series {
    std::string name;
    std::vector<std::size_t> columns;
    std::vector<std::string> labels;
  };
  const std::vector<Series> panels{
      {"cup x (m)", {si::kCupX}, {"cup"}},
      {"dice x (m)", {si::die(0), si::die(1), si::die(2)}, {"die 0", "die 1", "die 2"}},
      {"dice y (m)", {si::die(0) + 1, si::die(1) + 1, si::die(2) + 1}, {"die 0", "die 1", "die 2"}},
      {"cup angle (rad)", {si::kCupAngle}, {"cup"}},
      {"cup velocity", {si::kCupVx, si::kCupVy, si::kCupW}, {"vx (m/s)", "vy (m/s)", "w (rad/s)"}}};
  const int width = 1000, panel_h = 170, margin = 60, top = 40;
  cv::Mat img(top + panel_h * static_cast<int>(panels.size()) + 40, width, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::putText(img, title, {margin, 26}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {0, 0, 0}, 1, cv::LINE_AA);
  const std::array<cv::Scalar, 3> colours{cv::Scalar(200, 80, 40), cv::Scalar(60, 160, 60), cv::Scalar(60, 60, 210)};
  const double dt = world.physics.control_dt, t_end = static_cast<double>(states.size() - 1) * dt;
  for (std::size_t p = 0; p < panels.size(); ++p) {
    const int y0 = top + static_cast<int>(p) * panel_h, y1 = y0 + panel_h - 30;
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (const auto& s : states)
      for (auto c : panels[p].columns) lo = std::min(lo, s[c]), hi = std::max(hi, s[c]);
    if (hi - lo < 1e-9) hi = lo + 1.0;
    const double pad = 0.05 * (hi - lo);
    lo -= pad, hi += pad;
    cv::rectangle(img, {margin, y0}, {width - 20, y1}, {180, 180, 180});
    cv::putText(img, panels[p].name, {margin + 6, y0 + 16}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
    char tick[32];
    std::snprintf(tick, sizeof tick, "%.2f", hi);
    cv::putText(img, tick, {4, y0 + 12}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {90, 90, 90}, 1, cv::LINE_AA);
    std::snprintf(tick, sizeof tick, "%.2f", lo);
    cv::putText(img, tick, {4, y1}, cv::FONT_HERSHEY_SIMPLEX, 0.4, {90, 90, 90}, 1, cv::LINE_AA);
    for (std::size_t k = 0; k < panels[p].columns.size(); ++k) {
      std::vector<cv::Point> pts;
      for (std::size_t t = 0; t < states.size(); ++t) {
        const double x = margin + (width - 20 - margin) * (t * dt) / std::max(t_end, dt);
        const double y = y1 - (y1 - y0) * (states[t][panels[p].columns[k]] - lo) / (hi - lo);
        pts.emplace_back(static_cast<int>(x), static_cast<int>(y));
      }
      cv::polylines(img, pts, false, colours[k], 2, cv::LINE_AA);
      cv::putText(img, panels[p].labels[k], {width - 150, y0 + 16 + 16 * static_cast<int>(k)}, cv::FONT_HERSHEY_SIMPLEX,
                  0.45, colours[k], 1, cv::LINE_AA);
    }
  }
  char axis[64];
  std::snprintf(axis, sizeof axis, "time (s), 0 to %.2f", t_end);
  cv::putText(img, axis, {width / 2 - 80, img.rows - 12}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
  return Image{img.cols, img.rows, std::vector<std::uint8_t>(img.data, img.data + img.total() * img.elemSize())};
}


}  // namespace dicestack
