#include <dicestack/core/render.hpp>

#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/atomic_file.hpp>
#include <dicestack/core/error.hpp>
#include <dicestack/core/geometry.hpp>

#include "png_encoder.hpp"

namespace dicestack {
namespace {

namespace si = state_index;

struct Canvas {
  cv::Mat img;
  double ppm;
  // Sub-pixel coordinates (4 fractional bits) keep thin shapes smooth.
  static constexpr int kShift = 4;
  cv::Point px(Vec2 p) const {
    return {static_cast<int>(std::lround(p.x * ppm * (1 << kShift))),
            static_cast<int>(std::lround((img.rows - p.y * ppm) * (1 << kShift)))};
  }
  int len(double metres) const { return std::max(1, static_cast<int>(std::lround(metres * ppm))); }
};

const cv::Scalar kBackground(245, 240, 235), kWall(90, 90, 90), kCup(40, 110, 200), kInk(30, 30, 30);
const cv::Scalar kArm(170, 170, 160), kArmJoint(110, 110, 100);
const std::array<cv::Scalar, kDiceCount> kDieColour{cv::Scalar(80, 80, 220), cv::Scalar(80, 170, 60),
                                                    cv::Scalar(200, 120, 40)};

void draw_die(Canvas& c, const State& s, std::size_t i, const WorldConfig& config) {
  const std::size_t d = si::die(i);
  const Vec2 centre{s[d], s[d + 1]};
  const double angle = s[d + 2];
  std::vector<cv::Point> poly;
  for (const auto& v : die_vertices(config.dice)) poly.push_back(c.px(to_world(centre, angle, v)));
  cv::fillConvexPoly(c.img, poly, cv::Scalar(250, 250, 250), cv::LINE_AA, Canvas::kShift);
  cv::polylines(c.img, poly, true, kDieColour[i], 2, cv::LINE_AA, Canvas::kShift);
  // Pips: die i shows i + 1 spots, so the order of a stack can be read off the picture.
  const double h = config.dice.half_size * 0.5;
  const std::array<std::vector<Vec2>, 3> pips{{{{0, 0}}, {{-h, -h}, {h, h}}, {{-h, -h}, {0, 0}, {h, h}}}};
  for (const auto& p : pips[i])
    cv::circle(c.img, c.px(to_world(centre, angle, p)), c.len(config.dice.half_size * 0.16) << Canvas::kShift,
               kDieColour[i], cv::FILLED, cv::LINE_AA, Canvas::kShift);
}

void draw_text(cv::Mat& img, cv::Point origin, const std::string& text, int row, cv::Scalar colour) {
  cv::putText(img, text, cv::Point(origin.x, origin.y + 26 * row), cv::FONT_HERSHEY_SIMPLEX, 0.65, colour, 2,
              cv::LINE_AA);
}

}  // namespace

Image render_state(const State& s, const WorldConfig& config, const Hud& hud, const RenderOptions& options) {
  Image out;
  render_state_into(out, s, config, hud, options);
  return out;
}

void render_state_into(Image& out, const State& s, const WorldConfig& config, const Hud& hud,
                       const RenderOptions& options) {
  const auto& w = config.walls;
  const double ppm = options.pixels_per_metre;
  const int width = static_cast<int>(std::lround((w.right_x + w.left_x) * ppm));
  // The original window: a margin of left_x on every side of the walls' centre lines.
  const int height = static_cast<int>(std::lround((w.ceiling_y + w.left_x) * ppm));
  out.width = width;
  out.height = height;
  out.bgr.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3);
  Canvas c{cv::Mat(height, width, CV_8UC3, out.bgr.data()), ppm};
  c.img.setTo(kBackground);

  // Walls: axis-aligned bands (the inner faces of the rounded segments), drawn as rectangles.
  const double r = w.radius;
  const std::array<std::array<Vec2, 2>, 4> walls{{{{{w.left_x - r, w.floor_y - r}, {w.right_x + r, w.floor_y + r}}},
                                                  {{{w.left_x - r, w.floor_y - r}, {w.left_x + r, w.ceiling_y + r}}},
                                                  {{{w.right_x - r, w.floor_y - r}, {w.right_x + r, w.ceiling_y + r}}},
                                                  {{{w.left_x - r, w.ceiling_y - r}, {w.right_x + r, w.ceiling_y + r}}}}};
  for (const auto& box : walls) cv::rectangle(c.img, c.px(box[0]), c.px(box[1]), kWall, cv::FILLED, cv::LINE_8, Canvas::kShift);

  const CupGeometry cup = cup_geometry(config.cup);
  const Vec2 com{s[si::kCupX], s[si::kCupY]};
  // The arm behind the scene, in its rest posture for the cup's pose (a state holds the cup and
  // dice; the arm a world rebuilt at it would take).
  if (config.embodiment == Embodiment::arm) {
    const ArmPosture arm = arm_posture(config.arm, com);
    for (std::size_t i = 0; i < 3; ++i)
      cv::line(c.img, c.px(arm.joints[i]), c.px(arm.joints[i + 1]), kArm, 2 * c.len(config.arm.link_radius), cv::LINE_AA,
               Canvas::kShift);
    for (const Vec2 j : arm.joints) cv::circle(c.img, c.px(j), c.len(1.5 * config.arm.link_radius) << Canvas::kShift, kArmJoint, cv::FILLED, cv::LINE_AA, Canvas::kShift);
  }
  for (const auto& seg : cup.segments)
    cv::line(c.img, c.px(to_world(com, s[si::kCupAngle], seg.a)), c.px(to_world(com, s[si::kCupAngle], seg.b)), kCup,
             2 * c.len(seg.radius), cv::LINE_AA, Canvas::kShift);
  for (std::size_t i = 0; i < kDiceCount; ++i) draw_die(c, s, i, config);

  if (options.show_hud) {
    const Outcome& o = hud.outcome;
    char line[160];
    int row = 0;
    // Text starts inside the walls' top-left corner.
    const cv::Point at(static_cast<int>((w.left_x + w.radius) * ppm) + 14,
                       height - static_cast<int>((w.ceiling_y - w.radius) * ppm) + 28);
    if (!hud.title.empty()) draw_text(c.img, at, hud.title, row++, kInk);
    std::snprintf(line, sizeof line, "t = %.2f s   step %d", hud.step * config.physics.control_dt, hud.step);
    draw_text(c.img, at, line, row++, kInk);
    std::snprintf(line, sizeof line, "dice in cup: %d (most %d)", o.dice_in_cup_now, o.dice_in_cup);
    draw_text(c.img, at, line, row++, kInk);
    draw_text(c.img, at, std::string("stacked: ") + (o.stacked ? "yes" : "no"), row++, kInk);
    draw_text(c.img, at, std::string("wall contact: ") + (o.wall_contact ? "YES" : "no"), row++,
              o.wall_contact ? cv::Scalar(30, 30, 200) : kInk);
    if (o.realistic_success()) draw_text(c.img, at, "REALISTIC SUCCESS", row++, cv::Scalar(40, 150, 40));
  }
}

void write_png(const Image& image, const std::filesystem::path& path) {
  std::vector<std::uint8_t> png;
  try {
    png = encode_png(image);
  } catch (const InputError& e) {
    throw InputError(path.string() + ": " + e.what());
  }
  AtomicFile file(path, Ownership::unchecked("PNG image"));  // rendered images are deliberately not guarded
  file.stream().write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  file.commit();
}

}  // namespace dicestack
