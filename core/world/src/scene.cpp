#include "scene.hpp"

#include <cmath>
#include <mutex>
#include <new>
#include <vector>

#include <dicestack/core/geometry.hpp>

namespace dicestack::detail {
namespace {

namespace si = state_index;

// Box2D 2.4 lazily fills a static table of contact factories on the first contact, which is a
// data race when worlds in several threads collide for the first time; do it once up front.
void initialise_box2d_once() {
  static std::once_flag once;
  std::call_once(once, [] {
    b2World w(b2Vec2(0.0f, -10.0f));
    b2PolygonShape box;
    box.SetAsBox(1.0f, 1.0f);
    b2CircleShape circle;
    circle.m_radius = 1.0f;
    b2BodyDef def;
    def.type = b2_dynamicBody;
    b2Body* a = w.CreateBody(&def);
    a->CreateFixture(&box, 1.0f);
    b2Body* b = w.CreateBody(&def);
    b->CreateFixture(&circle, 1.0f);
    w.Step(1.0f / 60.0f, 1, 1);
  });
}

// Shrinks a convex counter-clockwise polygon by moving every edge inward by `d`, so that the
// Box2D skin of radius d around the result gives back the original outline.
std::vector<b2Vec2> inset_polygon(const std::vector<Vec2>& v, double d) {
  const std::size_t n = v.size();
  std::vector<b2Vec2> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 p = v[(i + n - 1) % n], q = v[i], r = v[(i + 1) % n];
    // Inward normals of edges p->q and q->r (counter-clockwise: inward is to the left).
    auto inward = [](Vec2 a, Vec2 b) {
      const double ex = b.x - a.x, ey = b.y - a.y, len = std::hypot(ex, ey);
      return Vec2{-ey / len, ex / len};
    };
    const Vec2 n1 = inward(p, q), n2 = inward(q, r);
    // The vertex moves along the bisector by d / cos(half the turn).
    const double bx = n1.x + n2.x, by = n1.y + n2.y;
    const double scale = 2.0 * d / (bx * bx + by * by);
    out[i].Set(static_cast<float>(q.x + bx * scale), static_cast<float>(q.y + by * scale));
  }
  return out;
}

// Metres in Box2D units, as float.
float box2d_length(double metres, double u) { return static_cast<float>(metres * u); }

// Adds the next fixture (id `next_id`, stored as user data id + 1) to `body`, massless.
void add_scene_fixture(Scene& scene, int& next_id, b2Body* body, const b2Shape& shape, double friction) {
  b2FixtureDef def;
  def.shape = &shape;
  def.density = 0.0f;  // mass data is set explicitly
  // Friction: Box2D mixes sqrt(a * b), Chipmunk (the original) a * b. Storing the squares
  // makes Box2D's mix the product.
  def.friction = static_cast<float>(friction * friction);
  def.restitution = 0.0f;
  def.userData.pointer = static_cast<uintptr_t>(next_id + 1);
  scene.fixtures[static_cast<std::size_t>(next_id++)] = body->CreateFixture(&def);
}

// Walls: static boxes covering each rounded segment's inner face (the corners lie inside
// the neighbouring walls, so the boxes and the capsules bound the same free space).
void add_wall_fixtures(Scene& scene, const WorldConfig& c, int& next_id) {
  const double u = scene.u;
  b2BodyDef ground_def;
  b2Body* ground = scene.world->CreateBody(&ground_def);
  const auto& w = c.walls;
  const double skin = b2_polygonRadius / u;
  const double mid_x = 0.5 * (w.left_x + w.right_x), mid_y = 0.5 * (w.floor_y + w.ceiling_y);
  const double half_w = 0.5 * (w.right_x - w.left_x) + w.radius, half_h = 0.5 * (w.ceiling_y - w.floor_y) + w.radius;
  const std::array<std::array<double, 4>, kWallFixtures> boxes{{{mid_x, w.floor_y, half_w, w.radius},
                                                               {w.left_x, mid_y, w.radius, half_h},
                                                               {w.right_x, mid_y, w.radius, half_h},
                                                               {mid_x, w.ceiling_y, half_w, w.radius}}};
  for (const auto& b : boxes) {
    b2PolygonShape box;
    box.SetAsBox(box2d_length(b[2] - skin, u), box2d_length(b[3] - skin, u),
                 b2Vec2(box2d_length(b[0], u), box2d_length(b[1], u)), 0.0f);
    add_scene_fixture(scene, next_id, ground, box, w.friction);
  }
}

// A dynamic body at the pose's position and angle, not yet moving.
b2Body* create_pose_body(Scene& scene, const Pose& p) {
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position.Set(box2d_length(p.x, scene.u), box2d_length(p.y, scene.u));
  def.angle = static_cast<float>(p.angle);
  return scene.world->CreateBody(&def);
}

// Gives `body` the pose's linear and angular velocity.
void set_pose_motion(const Scene& scene, b2Body* body, const Pose& p) {
  body->SetLinearVelocity(b2Vec2(box2d_length(p.vx, scene.u), box2d_length(p.vy, scene.u)));
  body->SetAngularVelocity(static_cast<float>(p.w));
}

// The cup body with its three segment fixtures and mass, at `pose`.
b2Body* add_cup_body(Scene& scene, const WorldConfig& c, const Pose& pose, int& next_id) {
  const double u = scene.u;
  // Each rounded segment is a thin box whose skin (m_radius) makes up the segment radius, so
  // faces sit exactly `radius` from the centre line and the ends are rounded.
  const CupGeometry cup = cup_geometry(c.cup);
  b2Body* cup_body = create_pose_body(scene, pose);
  for (const auto& s : cup.segments) {
    const double core = 0.1 * s.radius;
    const double len = std::hypot(s.b.x - s.a.x, s.b.y - s.a.y);
    b2PolygonShape seg;
    seg.SetAsBox(box2d_length(0.5 * len + core, u), box2d_length(core, u),
                 b2Vec2(box2d_length(0.5 * (s.a.x + s.b.x), u), box2d_length(0.5 * (s.a.y + s.b.y), u)),
                 static_cast<float>(std::atan2(s.b.y - s.a.y, s.b.x - s.a.x)));
    seg.m_radius = box2d_length(s.radius - core, u);
    add_scene_fixture(scene, next_id, cup_body, seg, c.cup.friction);
  }
  b2MassData cup_mass;
  cup_mass.mass = static_cast<float>(cup.mass);
  cup_mass.center.SetZero();
  cup_mass.I = static_cast<float>(cup.inertia * u * u);
  cup_body->SetMassData(&cup_mass);
  set_pose_motion(scene, cup_body, pose);
  return cup_body;
}

// The dice bodies, at poses[1..]: the octagon shrunk by Box2D's skin, so the skinned outline
// is the configured one.
void add_dice_bodies(Scene& scene, const WorldConfig& c, const std::array<Pose, kBodies>& poses, int& next_id) {
  const double u = scene.u;
  const auto verts = die_vertices(c.dice);
  std::vector<Vec2> scaled;
  for (const auto& v : verts) scaled.push_back({v.x * u, v.y * u});
  const auto inset = inset_polygon(scaled, b2_polygonRadius);
  b2PolygonShape die;
  die.Set(inset.data(), static_cast<int32>(inset.size()));
  b2MassData die_mass;
  die_mass.mass = static_cast<float>(c.dice.mass);
  die_mass.center.SetZero();
  die_mass.I = static_cast<float>(die_inertia(c.dice) * u * u);
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    b2Body* body = create_pose_body(scene, poses[i + 1]);
    add_scene_fixture(scene, next_id, body, die, c.dice.friction);
    body->SetMassData(&die_mass);
    set_pose_motion(scene, body, poses[i + 1]);
    scene.bodies[i + 1] = body;
  }
}

}  // namespace

std::array<Pose, kBodies> poses_of(const State& s) {
  std::array<Pose, kBodies> p;
  p[0] = {s[si::kCupX], s[si::kCupY], s[si::kCupAngle], s[si::kCupVx], s[si::kCupVy], s[si::kCupW]};
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    const std::size_t d = si::die(i);
    p[i + 1] = {s[d], s[d + 1], s[d + 2], s[d + 3], s[d + 4], s[d + 5]};
  }
  return p;
}

WorldStorage make_world_storage() { return WorldStorage(new std::byte[sizeof(b2World)]); }

Scene::Scene(const WorldConfig& c, const std::array<Pose, kBodies>& poses, std::byte* storage)
    : u(c.physics.units_per_metre) {
  initialise_box2d_once();
  world = new (storage) b2World(b2Vec2(box2d_length(c.physics.gravity.x, u), box2d_length(c.physics.gravity.y, u)));
  world->SetAllowSleeping(c.physics.allow_sleep);
  int next_id = 0;  // fixtures are numbered in the order they are added
  add_wall_fixtures(*this, c, next_id);
  bodies[0] = add_cup_body(*this, c, poses[0], next_id);
  add_dice_bodies(*this, c, poses, next_id);
}

}  // namespace dicestack::detail
