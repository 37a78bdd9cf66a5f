#include "scene.hpp"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <new>
#include <vector>

#include <dicestack/core/arm.hpp>
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

// In an arm world the links meet only the walls (they move in a plane in front of the dice).
constexpr uint16 kWallCategory = 0x0001, kLinkCategory = 0x0002, kSceneCategory = 0x0004;

b2Vec2 box2d_point(Vec2 p, double u) { return {box2d_length(p.x, u), box2d_length(p.y, u)}; }

// The arm holding the cup: link bodies in the rest posture for the cup's pose, moving so that
// the wrist follows the cup's velocity (or, given `links`, at the angles and rates its encoders
// read), and the four joints with their limits.
void add_arm(Scene& scene, const WorldConfig& c, const Pose& cup, const ArmLinks* links) {
  const double u = scene.u;
  const ArmConfig& arm = c.arm;
  for (b2Fixture* f : scene.fixtures)
    if (f->GetBody() != scene.fixtures[0]->GetBody()) {
      b2Filter filter;
      filter.categoryBits = kSceneCategory;
      f->SetFilterData(filter);
    }
  const ArmPosture posture = links ? arm_posture_of(arm, links->angles) : arm_posture(arm, {cup.x, cup.y});
  const auto rates = links ? links->rates : arm_link_rates(arm, posture.link_angles, {cup.vx, cup.vy});
  b2Vec2 joint_velocity(0.0f, 0.0f);  // of the link's near joint, Box2D units
  for (std::size_t i = 0; i < kArmLinks; ++i) {
    const double a = posture.link_angles[i], len = arm.link_lengths[i];
    const Vec2 from = posture.joints[i], to = posture.joints[i + 1];
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position = box2d_point({0.5 * (from.x + to.x), 0.5 * (from.y + to.y)}, u);
    def.angle = static_cast<float>(a);
    b2Body* body = scene.world->CreateBody(&def);
    const double core = 0.1 * arm.link_radius;
    b2PolygonShape shape;
    shape.SetAsBox(box2d_length(0.5 * len + core, u), box2d_length(core, u));
    shape.m_radius = box2d_length(arm.link_radius - core, u);
    b2FixtureDef fd;
    fd.shape = &shape;
    fd.density = 0.0f;
    fd.friction = static_cast<float>(c.walls.friction * c.walls.friction);
    fd.filter.categoryBits = kLinkCategory;
    fd.filter.maskBits = kWallCategory;
    fd.userData.pointer = static_cast<uintptr_t>(kFirstLinkFixture + static_cast<int>(i) + 1);
    scene.link_fixtures.push_back(body->CreateFixture(&fd));
    b2MassData mass;
    mass.mass = static_cast<float>(arm.link_masses[i]);
    mass.center.SetZero();
    mass.I = static_cast<float>(arm.link_masses[i] * len * len / 12.0 * u * u);
    body->SetMassData(&mass);
    // The link's centre moves with its near joint plus half its length turning at its rate.
    const b2Vec2 turn(static_cast<float>(-std::sin(a) * rates[i] * u), static_cast<float>(std::cos(a) * rates[i] * u));
    body->SetLinearVelocity(joint_velocity + static_cast<float>(0.5 * len) * turn);
    body->SetAngularVelocity(static_cast<float>(rates[i]));
    joint_velocity += static_cast<float>(len) * turn;
    scene.links.push_back(body);
  }
  b2Body* ground = scene.fixtures[0]->GetBody();
  const std::array<b2Body*, kArmJoints + 1> chain{ground, scene.links[0], scene.links[1], scene.links[2], scene.bodies[0]};
  for (std::size_t j = 0; j < kArmJoints; ++j) {
    b2RevoluteJointDef def;
    def.bodyA = chain[j];
    def.bodyB = chain[j + 1];
    def.localAnchorA = j == 0 ? box2d_point(arm.base, u) : b2Vec2(box2d_length(0.5 * arm.link_lengths[j - 1], u), 0.0f);
    def.localAnchorB = j < kArmLinks ? b2Vec2(box2d_length(-0.5 * arm.link_lengths[j], u), 0.0f) : b2Vec2(0.0f, 0.0f);
    def.referenceAngle = 0.0f;  // a joint's angle is its body's angle minus the previous body's
    def.enableLimit = true;
    def.lowerAngle = static_cast<float>(arm.joint_lower[j]);
    def.upperAngle = static_cast<float>(arm.joint_upper[j]);
    def.collideConnected = false;
    scene.joints.push_back(static_cast<b2RevoluteJoint*>(scene.world->CreateJoint(&def)));
  }
}

}  // namespace

std::array<double, 3> Scene::link_angles() const {
  std::array<double, 3> a{};
  for (std::size_t i = 0; i < links.size(); ++i) a[i] = links[i]->GetAngle();
  return a;
}

std::array<double, 3> Scene::link_rates() const {
  std::array<double, 3> r{};
  for (std::size_t i = 0; i < links.size(); ++i) r[i] = links[i]->GetAngularVelocity();
  return r;
}

void Scene::drive_arm(const ArmConfig& arm, const Action& target, double dt, Vec2 gravity) {
  ArmMotion now;
  const std::array<b2Body*, 4> chain{links[0], links[1], links[2], bodies[0]};
  for (std::size_t i = 0; i < 4; ++i) {
    now.angles[i] = chain[i]->GetAngle();
    now.rates[i] = chain[i]->GetAngularVelocity();
  }
  now.cup_velocity = {bodies[0]->GetLinearVelocity().x / u, bodies[0]->GetLinearVelocity().y / u};
  now.cup_mass = bodies[0]->GetMass();
  now.cup_inertia = bodies[0]->GetInertia() / (u * u);
  torques = arm_torques(arm, now, {target[0], target[1]}, target[2], dt, gravity);
  apply_joint_torques();
}

void Scene::hold_joint_torques(const ArmConfig& arm, const std::array<double, 4>& wanted) {
  const std::array<const b2Body*, 4> chain{links[0], links[1], links[2], bodies[0]};
  for (std::size_t j = 0; j < 4; ++j) {
    const double rate = chain[j]->GetAngularVelocity() - (j > 0 ? chain[j - 1]->GetAngularVelocity() : 0.0);
    const double tau = std::clamp(wanted[j], -arm.torque_limit[j], arm.torque_limit[j]);
    torques[j] = std::abs(rate) >= arm.speed_limit[j] && tau * rate > 0.0 ? 0.0 : tau;
  }
  apply_joint_torques();
}

void Scene::apply_joint_torques() {
  // Joint j turns body j by its torque and the body before it back (the ground takes the
  // shoulder's reaction).
  const std::array<b2Body*, 4> chain{links[0], links[1], links[2], bodies[0]};
  for (std::size_t i = 0; i < 4; ++i) torque_sum[i] += torques[i];
  for (std::size_t i = 0; i < 4; ++i)
    chain[i]->ApplyTorque(static_cast<float>((torques[i] - (i + 1 < 4 ? torques[i + 1] : 0.0)) * u * u), true);
}

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

Scene::Scene(const WorldConfig& c, const std::array<Pose, kBodies>& given, std::byte* storage, const ArmLinks* encoders)
    : u(c.physics.units_per_metre) {
  std::array<Pose, kBodies> poses = given;
  if (encoders) {  // the cup at the wrist the links reach, moving as they move it
    const ArmPosture p = arm_posture_of(c.arm, encoders->angles);
    poses[0].x = p.joints[3].x;
    poses[0].y = p.joints[3].y;
    const Vec2 v = arm_wrist_velocity(c.arm, encoders->angles, encoders->rates);
    poses[0].vx = v.x;
    poses[0].vy = v.y;
  }
  initialise_box2d_once();
  world = new (storage) b2World(b2Vec2(box2d_length(c.physics.gravity.x, u), box2d_length(c.physics.gravity.y, u)));
  world->SetAllowSleeping(c.physics.allow_sleep);
  int next_id = 0;  // fixtures are numbered in the order they are added
  add_wall_fixtures(*this, c, next_id);
  bodies[0] = add_cup_body(*this, c, poses[0], next_id);
  add_dice_bodies(*this, c, poses, next_id);
  if (c.embodiment == Embodiment::arm) add_arm(*this, c, poses[0], encoders);
}

}  // namespace dicestack::detail
