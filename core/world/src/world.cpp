#include <dicestack/core/world.hpp>

#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>

#include "box2d_access.hpp"
#include "byte_io.hpp"
#include <dicestack/core/error.hpp>
#include <dicestack/core/geometry.hpp>
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {
namespace {

namespace si = state_index;
using detail::get;

constexpr int kWallFixtures = 4, kCupFixtures = 3, kFixtureCount = kWallFixtures + kCupFixtures + 3;
constexpr int kBodies = 4;  // cup, die 0, die 1, die 2 (the static walls carry no state)

// Fixture ids, stored as user data (id + 1, so that 0 means "not ours").
constexpr int kFirstCupFixture = kWallFixtures, kFirstDieFixture = kWallFixtures + kCupFixtures;

ShapeKind kind_of_fixture(int id) {
  if (id < kWallFixtures) return static_cast<ShapeKind>(id);
  return id < kFirstDieFixture ? ShapeKind::cup : ShapeKind::die;
}

int fixture_id(b2Fixture* f) { return static_cast<int>(f->GetUserData().pointer) - 1; }

bool is_side_wall_or_ceiling(int id) { return id >= 1 && id < kWallFixtures; }

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

struct Pose {
  double x = 0, y = 0, angle = 0, vx = 0, vy = 0, w = 0;
};

std::array<Pose, kBodies> poses_of(const State& s) {
  std::array<Pose, kBodies> p;
  p[0] = {s[si::kCupX], s[si::kCupY], s[si::kCupAngle], s[si::kCupVx], s[si::kCupVy], s[si::kCupW]};
  for (std::size_t i = 0; i < kDiceCount; ++i) {
    const std::size_t d = si::die(i);
    p[i + 1] = {s[d], s[d + 1], s[d + 2], s[d + 3], s[d + 4], s[d + 5]};
  }
  return p;
}

// Memory for one b2World. The object holds Box2D's 100 KB stack allocator inline; rebuilding
// a scene in the same block avoids a large allocation per reset (measured: 70 us -> 3 us).
using WorldStorage = std::unique_ptr<std::byte[]>;
WorldStorage make_world_storage() { return WorldStorage(new std::byte[sizeof(b2World)]); }

// The scene in Box2D units, built the same way for World and for the bare benchmark loop.
struct Scene {
  double u = 10.0;  // Box2D units per metre
  b2World* world = nullptr;               // constructed in caller-owned storage
  std::array<b2Body*, kBodies> bodies{};  // cup, dice
  std::array<b2Fixture*, kFixtureCount> fixtures{};

  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
  ~Scene() { world->~b2World(); }

  Scene(const WorldConfig& c, const std::array<Pose, kBodies>& poses, std::byte* storage)
      : u(c.physics.units_per_metre) {
    initialise_box2d_once();
    const auto fu = [this](double metres) { return static_cast<float>(metres * u); };
    world = new (storage) b2World(b2Vec2(fu(c.physics.gravity.x), fu(c.physics.gravity.y)));
    world->SetAllowSleeping(c.physics.allow_sleep);

    // Friction: Box2D mixes sqrt(a * b), Chipmunk (the original) a * b. Storing the squares
    // makes Box2D's mix the product.
    const auto squared = [](double f) { return static_cast<float>(f * f); };
    int next_id = 0;
    auto add = [&](b2Body* body, const b2Shape& shape, double friction) {
      b2FixtureDef def;
      def.shape = &shape;
      def.density = 0.0f;  // mass data is set explicitly below
      def.friction = squared(friction);
      def.restitution = 0.0f;
      def.userData.pointer = static_cast<uintptr_t>(next_id + 1);
      fixtures[static_cast<std::size_t>(next_id++)] = body->CreateFixture(&def);
    };

    // Walls: static boxes covering each rounded segment's inner face (the corners lie inside
    // the neighbouring walls, so the boxes and the capsules bound the same free space).
    b2BodyDef ground_def;
    b2Body* ground = world->CreateBody(&ground_def);
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
      box.SetAsBox(fu(b[2] - skin), fu(b[3] - skin), b2Vec2(fu(b[0]), fu(b[1])), 0.0f);
      add(ground, box, w.friction);
    }

    auto make_body = [&](const Pose& p) {
      b2BodyDef def;
      def.type = b2_dynamicBody;
      def.position.Set(fu(p.x), fu(p.y));
      def.angle = static_cast<float>(p.angle);
      return world->CreateBody(&def);
    };
    auto set_motion = [&](b2Body* body, const Pose& p) {
      body->SetLinearVelocity(b2Vec2(fu(p.vx), fu(p.vy)));
      body->SetAngularVelocity(static_cast<float>(p.w));
    };

    // Cup: each rounded segment is a thin box whose skin (m_radius) makes up the segment
    // radius, so faces sit exactly `radius` from the centre line and the ends are rounded.
    const CupGeometry cup = cup_geometry(c.cup);
    b2Body* cup_body = make_body(poses[0]);
    for (const auto& s : cup.segments) {
      const double core = 0.1 * s.radius;
      const double len = std::hypot(s.b.x - s.a.x, s.b.y - s.a.y);
      b2PolygonShape seg;
      seg.SetAsBox(fu(0.5 * len + core), fu(core), b2Vec2(fu(0.5 * (s.a.x + s.b.x)), fu(0.5 * (s.a.y + s.b.y))),
                   static_cast<float>(std::atan2(s.b.y - s.a.y, s.b.x - s.a.x)));
      seg.m_radius = fu(s.radius - core);
      add(cup_body, seg, c.cup.friction);
    }
    b2MassData cup_mass;
    cup_mass.mass = static_cast<float>(cup.mass);
    cup_mass.center.SetZero();
    cup_mass.I = static_cast<float>(cup.inertia * u * u);
    cup_body->SetMassData(&cup_mass);
    set_motion(cup_body, poses[0]);
    bodies[0] = cup_body;

    // Dice: the octagon shrunk by Box2D's skin, so the skinned outline is the configured one.
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
      b2Body* body = make_body(poses[i + 1]);
      add(body, die, c.dice.friction);
      body->SetMassData(&die_mass);
      set_motion(body, poses[i + 1]);
      bodies[i + 1] = body;
    }
  }

  b2ContactManager& contacts() const { return const_cast<b2ContactManager&>(world->GetContactManager()); }
};

}  // namespace

// ---- snapshot contents --------------------------------------------------------------------

struct WorldSnapshot::Data {
  struct Body {
    b2Transform xf;
    b2Sweep sweep;
    b2Vec2 velocity;
    float angular_velocity;
    uint16 flags;
    float sleep_time;
  };
  struct Contact {
    int fixture_a, fixture_b, child_a, child_b;
    uint32 flags;
    b2Manifold manifold;
    int32 toi_count;
    float toi;
  };
  State state{};
  std::array<Body, kBodies> bodies{};
  std::vector<b2TreeNode> tree_nodes;
  std::vector<char> tree_leaf;  // node holds a fixture proxy
  int32 tree_root = 0, tree_node_count = 0, tree_free_list = 0, tree_insertions = 0;
  std::vector<int32> move_buffer;
  std::vector<Contact> contacts;  // in the world's contact-list order
  float inv_dt0 = 0.0f;
  bool new_contacts = false, step_complete = true;
};

WorldSnapshot::WorldSnapshot() = default;
WorldSnapshot::~WorldSnapshot() = default;
WorldSnapshot::WorldSnapshot(const WorldSnapshot&) = default;
WorldSnapshot& WorldSnapshot::operator=(const WorldSnapshot&) = default;

const State& WorldSnapshot::state() const {
  if (!data_) throw InputError("world snapshot: empty (default-constructed) snapshot has no state");
  return data_->state;
}

namespace {

constexpr std::uint32_t kSnapshotMarker = 0x44534e50;  // "DSNP"; read back swapped on another byte order
constexpr std::uint32_t kSnapshotVersion = 1;
constexpr std::int32_t kMaxTreeNodes = 1 << 16;

void put_vec(detail::ByteWriter& w, const b2Vec2& v) {
  w.put(v.x);
  w.put(v.y);
}

b2Vec2 get_vec(detail::ByteReader& r, std::string_view field) {
  const float x = r.get_finite<float>(field);
  return {x, r.get_finite<float>(field)};
}

// Manifold points past pointCount and a contact's time of impact may hold stale values; they
// are copied, never checked.
b2Vec2 get_raw_vec(detail::ByteReader& r) {
  const float x = r.get<float>();
  return {x, r.get<float>()};
}

}  // namespace

std::string WorldSnapshot::to_bytes() const {
  if (!data_) throw InputError("world snapshot: an empty (default-constructed) snapshot has no bytes");
  const Data& d = *data_;
  detail::ByteWriter w;
  w.put(kSnapshotMarker);
  w.put(kSnapshotVersion);
  for (double v : d.state) w.put(v);
  for (const auto& b : d.bodies) {
    put_vec(w, b.xf.p);
    w.put(b.xf.q.s);
    w.put(b.xf.q.c);
    put_vec(w, b.sweep.localCenter);
    put_vec(w, b.sweep.c0);
    put_vec(w, b.sweep.c);
    w.put(b.sweep.a0);
    w.put(b.sweep.a);
    w.put(b.sweep.alpha0);
    put_vec(w, b.velocity);
    w.put(b.angular_velocity);
    w.put(b.flags);
    w.put(b.sleep_time);
  }
  w.put(static_cast<std::int32_t>(d.tree_nodes.size()));
  for (std::size_t i = 0; i < d.tree_nodes.size(); ++i) {
    const b2TreeNode& n = d.tree_nodes[i];
    put_vec(w, n.aabb.lowerBound);
    put_vec(w, n.aabb.upperBound);
    w.put(n.parent);
    w.put(n.child1);
    w.put(n.child2);
    w.put(n.height);
    std::uint8_t moved;  // a free node's flag may hold any byte: copied as a byte, never read as bool
    std::memcpy(&moved, &n.moved, 1);
    w.put(moved);
    w.put(static_cast<std::uint8_t>(d.tree_leaf[i] != 0));
  }
  w.put(d.tree_root);
  w.put(d.tree_node_count);
  w.put(d.tree_free_list);
  w.put(d.tree_insertions);
  w.put(static_cast<std::int32_t>(d.move_buffer.size()));
  for (int32 m : d.move_buffer) w.put(m);
  w.put(static_cast<std::int32_t>(d.contacts.size()));
  for (const auto& c : d.contacts) {
    w.put(c.fixture_a);
    w.put(c.fixture_b);
    w.put(c.child_a);
    w.put(c.child_b);
    w.put(c.flags);
    for (const auto& p : c.manifold.points) {
      put_vec(w, p.localPoint);
      w.put(p.normalImpulse);
      w.put(p.tangentImpulse);
      w.put(p.id.key);
    }
    put_vec(w, c.manifold.localNormal);
    put_vec(w, c.manifold.localPoint);
    w.put(static_cast<std::int32_t>(c.manifold.type));
    w.put(c.manifold.pointCount);
    w.put(c.toi_count);
    w.put(c.toi);
  }
  w.put(d.inv_dt0);
  w.put(static_cast<std::uint8_t>(d.new_contacts));
  w.put(static_cast<std::uint8_t>(d.step_complete));
  return w.finish();
}

WorldSnapshot WorldSnapshot::from_bytes(std::string_view bytes) {
  detail::ByteReader r(bytes, "world snapshot bytes");
  if (r.get<std::uint32_t>() != kSnapshotMarker) r.fail("not a dicestack world snapshot (or another byte order)");
  const auto version = r.get<std::uint32_t>();
  if (version != kSnapshotVersion)
    r.fail("version " + std::to_string(version) + ", this dicestack reads " + std::to_string(kSnapshotVersion));
  auto d = std::make_shared<Data>();
  for (double& v : d->state) v = r.get_finite<double>("state");
  for (auto& b : d->bodies) {
    b.xf.p = get_vec(r, "body position");
    b.xf.q.s = r.get_finite<float>("body rotation");
    b.xf.q.c = r.get_finite<float>("body rotation");
    b.sweep.localCenter = get_vec(r, "body sweep");
    b.sweep.c0 = get_vec(r, "body sweep");
    b.sweep.c = get_vec(r, "body sweep");
    b.sweep.a0 = r.get_finite<float>("body sweep");
    b.sweep.a = r.get_finite<float>("body sweep");
    b.sweep.alpha0 = r.get_finite<float>("body sweep");
    b.velocity = get_vec(r, "body velocity");
    b.angular_velocity = r.get_finite<float>("body angular velocity");
    b.flags = r.get<uint16>();
    b.sleep_time = r.get_finite<float>("body sleep time");
  }
  const int32 capacity = r.get_in<std::int32_t>(1, kMaxTreeNodes, "broad-phase capacity");
  const auto node_index = [&](std::string_view field) { return r.get_in<std::int32_t>(b2_nullNode, capacity - 1, field); };
  d->tree_nodes.resize(static_cast<std::size_t>(capacity));
  d->tree_leaf.resize(static_cast<std::size_t>(capacity));
  for (int32 i = 0; i < capacity; ++i) {
    b2TreeNode& n = d->tree_nodes[static_cast<std::size_t>(i)];
    // A free node (height -1) keeps only its free-list link; Box2D leaves the rest of a node
    // it grew into uninitialised, so only nodes in use are checked.
    n.aabb.lowerBound = get_raw_vec(r);
    n.aabb.upperBound = get_raw_vec(r);
    n.userData = nullptr;
    n.parent = r.get<int32>();
    n.child1 = r.get<int32>();
    n.child2 = r.get<int32>();
    n.height = r.get_in<std::int32_t>(-1, capacity, "broad-phase height");
    const auto moved = r.get<std::uint8_t>();
    std::memcpy(&n.moved, &moved, 1);
    const bool leaf = r.get_in<std::uint8_t>(0, 1, "broad-phase leaf flag") != 0;
    if (leaf != (n.height == 0)) r.fail("broad-phase node " + std::to_string(i) + " is a leaf only by its flag");
    d->tree_leaf[static_cast<std::size_t>(i)] = leaf;
    const auto check_index = [&](int32 index, std::string_view field) {
      if (index < b2_nullNode || index >= capacity)
        r.fail(std::string(field) + " of broad-phase node " + std::to_string(i) + " is " + std::to_string(index) +
               ", outside [-1, " + std::to_string(capacity - 1) + "]");
    };
    check_index(n.parent, "parent");
    if (n.height < 0) continue;
    if (moved > 1) r.fail("broad-phase node " + std::to_string(i) + " has a flag that is not 0 or 1");
    check_index(n.child1, "child");
    check_index(n.child2, "child");
    for (float v : {n.aabb.lowerBound.x, n.aabb.lowerBound.y, n.aabb.upperBound.x, n.aabb.upperBound.y})
      if (!std::isfinite(v)) r.fail("broad-phase node " + std::to_string(i) + " has a box that is not finite");
  }
  d->tree_root = node_index("broad-phase root");
  d->tree_node_count = r.get_in<std::int32_t>(0, capacity, "broad-phase node count");
  d->tree_free_list = node_index("broad-phase free list");
  d->tree_insertions = r.get_in<std::int32_t>(0, std::numeric_limits<std::int32_t>::max(), "broad-phase insertions");
  const auto moves = r.get_in<std::int32_t>(0, capacity, "broad-phase move count");
  for (std::int32_t i = 0; i < moves; ++i) d->move_buffer.push_back(node_index("broad-phase move"));
  const auto contacts = r.get_in<std::int32_t>(0, kFixtureCount * kFixtureCount, "contact count");
  for (std::int32_t i = 0; i < contacts; ++i) {
    Data::Contact c{};
    c.fixture_a = r.get_in<std::int32_t>(0, kFixtureCount - 1, "contact fixture");
    c.fixture_b = r.get_in<std::int32_t>(0, kFixtureCount - 1, "contact fixture");
    c.child_a = r.get_in<std::int32_t>(0, 0, "contact child");  // every shape is one polygon
    c.child_b = r.get_in<std::int32_t>(0, 0, "contact child");
    c.flags = r.get<uint32>();
    for (auto& p : c.manifold.points) {
      p.localPoint = get_raw_vec(r);
      p.normalImpulse = r.get<float>();
      p.tangentImpulse = r.get<float>();
      p.id.key = r.get<uint32>();
    }
    c.manifold.localNormal = get_raw_vec(r);
    c.manifold.localPoint = get_raw_vec(r);
    c.manifold.type = static_cast<b2Manifold::Type>(r.get_in<std::int32_t>(0, 2, "manifold type"));
    c.manifold.pointCount = r.get_in<std::int32_t>(0, b2_maxManifoldPoints, "manifold point count");
    c.toi_count = r.get<int32>();
    c.toi = r.get<float>();
    d->contacts.push_back(c);
  }
  d->inv_dt0 = r.get_finite<float>("inverse time step");
  d->new_contacts = r.get_in<std::uint8_t>(0, 1, "world flag") != 0;
  d->step_complete = r.get_in<std::uint8_t>(0, 1, "world flag") != 0;
  r.expect_end();
  WorldSnapshot snap;
  snap.data_ = std::move(d);
  return snap;
}

// ---- World --------------------------------------------------------------------------------

struct World::Impl {
  WorldConfig config;
  float sub_dt;
  float wall_contact_gap;  // Box2D units
  WorldStorage storage = make_world_storage();
  std::optional<Scene> scene;  // lives in `storage`

  // Replaces the scene; the old one is destroyed first so that both use the same storage.
  Scene& rebuild(const std::array<Pose, kBodies>& poses) {
    scene.reset();
    return scene.emplace(config, poses, storage.get());
  }

  explicit Impl(const WorldConfig& c) : config(c) {
    validate(config);
    sub_dt = static_cast<float>(config.physics.control_dt / config.physics.substeps);
    wall_contact_gap = static_cast<float>(config.judge.wall_contact_distance * config.physics.units_per_metre);
  }

  bool touches_wall() const {
    for (b2Contact* c = scene->world->GetContactList(); c; c = c->GetNext()) {
      if (!c->IsTouching()) continue;
      const int a = fixture_id(c->GetFixtureA()), b = fixture_id(c->GetFixtureB());
      if (!is_side_wall_or_ceiling(a) && !is_side_wall_or_ceiling(b)) continue;
      b2WorldManifold wm;
      c->GetWorldManifold(&wm);
      for (int32 i = 0; i < c->GetManifold()->pointCount; ++i)
        if (wm.separations[i] <= wall_contact_gap) return true;
    }
    return false;
  }

  State state() const {
    State s{};
    const double u = scene->u;
    auto put = [&](std::size_t at, const b2Body* b) {
      s[at] = b->GetPosition().x / u;
      s[at + 1] = b->GetPosition().y / u;
      s[at + 2] = b->GetAngle();
    };
    auto put_velocity = [&](std::size_t at, const b2Body* b) {
      s[at] = b->GetLinearVelocity().x / u;
      s[at + 1] = b->GetLinearVelocity().y / u;
      s[at + 2] = b->GetAngularVelocity();
    };
    put(si::kCupX, scene->bodies[0]);
    put_velocity(si::kCupVx, scene->bodies[0]);
    for (std::size_t i = 0; i < kDiceCount; ++i) {
      put(si::die(i), scene->bodies[i + 1]);
      put_velocity(si::die(i) + 3, scene->bodies[i + 1]);
    }
    return s;
  }
};

World::World(const WorldConfig& config) : World(config, paper_start_state(config)) {}

World::World(const WorldConfig& config, const State& state) : impl_(std::make_unique<Impl>(config)) {
  set_state(state);
}

World::~World() = default;
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;

const WorldConfig& World::config() const { return impl_->config; }

State World::state() const { return impl_->state(); }

void World::set_state(const State& state) {
  require_finite(state, "world state");
  impl_->rebuild(poses_of(state));
}

bool World::step(const Action& dv) {
  require_finite(dv, "action");
  Scene& sc = *impl_->scene;
  b2Body* cup = sc.bodies[0];
  b2Vec2 v = cup->GetLinearVelocity();
  v.x += static_cast<float>(dv[0] * sc.u);
  v.y += static_cast<float>(dv[1] * sc.u);
  cup->SetLinearVelocity(v);
  cup->SetAngularVelocity(cup->GetAngularVelocity() + static_cast<float>(dv[2]));
  const int vel_it = impl_->config.physics.velocity_iterations, pos_it = impl_->config.physics.position_iterations;
  bool wall = false;
  for (int k = 0; k < impl_->config.physics.substeps; ++k) {
    sc.world->Step(impl_->sub_dt, vel_it, pos_it);
    wall = wall || impl_->touches_wall();
  }
  return wall;
}

WorldSnapshot World::snapshot() const {
  const Scene& sc = *impl_->scene;
  auto data = std::make_shared<WorldSnapshot::Data>();
  data->state = impl_->state();
  for (std::size_t i = 0; i < kBodies; ++i) {
    b2Body& b = *sc.bodies[i];
    data->bodies[i] = {get<detail::BodyXf>(b), get<detail::BodySweep>(b), b.GetLinearVelocity(),
                       b.GetAngularVelocity(), get<detail::BodyFlags>(b), get<detail::BodySleepTime>(b)};
  }
  b2BroadPhase& bp = sc.contacts().m_broadPhase;
  b2DynamicTree& tree = get<detail::BroadPhaseTree>(bp);
  const b2TreeNode* nodes = get<detail::TreeNodes>(tree);
  const int32 capacity = get<detail::TreeNodeCapacity>(tree);
  data->tree_nodes.assign(nodes, nodes + capacity);
  data->tree_leaf.resize(static_cast<std::size_t>(capacity));
  for (int32 i = 0; i < capacity; ++i) {
    data->tree_leaf[static_cast<std::size_t>(i)] = nodes[i].height == 0;  // free nodes are -1
    data->tree_nodes[static_cast<std::size_t>(i)].userData = nullptr;
  }
  data->tree_root = get<detail::TreeRoot>(tree);
  data->tree_node_count = get<detail::TreeNodeCount>(tree);
  data->tree_free_list = get<detail::TreeFreeList>(tree);
  data->tree_insertions = get<detail::TreeInsertionCount>(tree);
  const int32* moves = get<detail::BroadPhaseMoveBuffer>(bp);
  data->move_buffer.assign(moves, moves + get<detail::BroadPhaseMoveCount>(bp));
  for (b2Contact* c = sc.world->GetContactList(); c; c = c->GetNext()) {
    data->contacts.push_back({fixture_id(c->GetFixtureA()), fixture_id(c->GetFixtureB()), c->GetChildIndexA(),
                              c->GetChildIndexB(), get<detail::ContactFlags>(*c), *c->GetManifold(),
                              get<detail::ContactToiCount>(*c), get<detail::ContactToi>(*c)});
    // Box2D sets a manifold's type only when the shapes touch: with no points it is whatever the
    // contact's memory held before (never read by Box2D). Store a fixed value, never that byte.
    b2Manifold& m = data->contacts.back().manifold;
    if (m.pointCount == 0) m.type = b2Manifold::e_circles;
  }
  b2World& w = *sc.world;
  data->inv_dt0 = get<detail::WorldInvDt0>(w);
  data->new_contacts = get<detail::WorldNewContacts>(w);
  data->step_complete = get<detail::WorldStepComplete>(w);
  WorldSnapshot snap;
  snap.data_ = std::move(data);
  return snap;
}

void World::restore(const WorldSnapshot& snapshot) {
  if (!snapshot.valid()) throw InputError("world snapshot: cannot restore an empty snapshot");
  const WorldSnapshot::Data& d = *snapshot.data_;
  // A fresh scene has the same body, fixture and proxy order as every scene built from this
  // config; the snapshot then overwrites what history changed.
  Scene* scene = &impl_->rebuild(poses_of(d.state));
  for (std::size_t i = 0; i < kBodies; ++i) {
    b2Body& b = *scene->bodies[i];
    const auto& s = d.bodies[i];
    get<detail::BodyXf>(b) = s.xf;
    get<detail::BodySweep>(b) = s.sweep;
    b.SetLinearVelocity(s.velocity);
    b.SetAngularVelocity(s.angular_velocity);
  }

  b2ContactManager& cm = scene->contacts();
  b2BroadPhase& bp = cm.m_broadPhase;
  b2DynamicTree& tree = get<detail::BroadPhaseTree>(bp);
  b2TreeNode* nodes = get<detail::TreeNodes>(tree);
  if (get<detail::TreeNodeCapacity>(tree) != static_cast<int32>(d.tree_nodes.size()))
    throw std::logic_error("world snapshot: broad-phase capacity differs; was it taken with another config?");
  for (std::size_t i = 0; i < d.tree_nodes.size(); ++i) {
    void* proxy = nodes[i].userData;
    if (d.tree_leaf[i] && (proxy == nullptr || nodes[i].height != 0))
      throw std::logic_error("world snapshot: broad-phase proxy ids differ; was it taken with another config? node " + std::to_string(i) + " height " + std::to_string(d.tree_nodes[i].height) + " now height " + std::to_string(nodes[i].height));
    nodes[i] = d.tree_nodes[i];
    nodes[i].userData = d.tree_leaf[i] ? proxy : nullptr;
  }
  get<detail::TreeRoot>(tree) = d.tree_root;
  get<detail::TreeNodeCount>(tree) = d.tree_node_count;
  get<detail::TreeFreeList>(tree) = d.tree_free_list;
  get<detail::TreeInsertionCount>(tree) = d.tree_insertions;
  if (get<detail::BroadPhaseMoveCapacity>(bp) < static_cast<int32>(d.move_buffer.size()))
    throw std::logic_error("world snapshot: broad-phase move buffer too small");
  std::copy(d.move_buffer.begin(), d.move_buffer.end(), get<detail::BroadPhaseMoveBuffer>(bp));
  get<detail::BroadPhaseMoveCount>(bp) = static_cast<int32>(d.move_buffer.size());

  // AddPair prepends, so adding in reverse rebuilds the world's and every body's contact list
  // in the original order (both lists are newest-first in Box2D).
  for (auto it = d.contacts.rbegin(); it != d.contacts.rend(); ++it) {
    b2Fixture* fa = scene->fixtures[static_cast<std::size_t>(it->fixture_a)];
    b2Fixture* fb = scene->fixtures[static_cast<std::size_t>(it->fixture_b)];
    cm.AddPair(get<detail::FixtureProxies>(*fa) + it->child_a, get<detail::FixtureProxies>(*fb) + it->child_b);
    b2Contact* made = cm.m_contactList;
    if (made == nullptr || made->GetFixtureA() != fa || made->GetFixtureB() != fb)
      throw std::logic_error("world snapshot: contact could not be recreated in its original order");
    *made->GetManifold() = it->manifold;
    get<detail::ContactFlags>(*made) = it->flags;
    get<detail::ContactToiCount>(*made) = it->toi_count;
    get<detail::ContactToi>(*made) = it->toi;
  }
  // AddPair wakes bodies; put back the recorded sleep state.
  for (std::size_t i = 0; i < kBodies; ++i) {
    get<detail::BodyFlags>(*scene->bodies[i]) = d.bodies[i].flags;
    get<detail::BodySleepTime>(*scene->bodies[i]) = d.bodies[i].sleep_time;
  }
  b2World& w = *scene->world;
  get<detail::WorldInvDt0>(w) = d.inv_dt0;
  get<detail::WorldNewContacts>(w) = d.new_contacts;
  get<detail::WorldStepComplete>(w) = d.step_complete;
}

std::vector<ShapeOutline> World::outlines() const {
  const Scene& sc = *impl_->scene;
  std::vector<ShapeOutline> out;
  for (std::size_t id = 0; id < sc.fixtures.size(); ++id) {
    const b2Fixture* f = sc.fixtures[id];
    const auto* poly = static_cast<const b2PolygonShape*>(f->GetShape());
    const b2Transform& xf = f->GetBody()->GetTransform();
    ShapeOutline o;
    o.kind = kind_of_fixture(static_cast<int>(id));
    o.index = o.kind == ShapeKind::cup ? static_cast<int>(id) - kFirstCupFixture
              : o.kind == ShapeKind::die ? static_cast<int>(id) - kFirstDieFixture
                                         : 0;
    o.radius = poly->m_radius / sc.u;
    for (int32 i = 0; i < poly->m_count; ++i) {
      const b2Vec2 p = b2Mul(xf, poly->m_vertices[i]);
      o.points.push_back({p.x / sc.u, p.y / sc.u});
    }
    out.push_back(std::move(o));
  }
  return out;
}

bool World::touching_walls() {
  impl_->scene->world->Step(0.0f, 1, 1);  // finds contacts and their manifolds; dt = 0 moves nothing
  return impl_->touches_wall();
}

bool World::has_overlaps(double tolerance) {
  Scene& sc = *impl_->scene;
  sc.world->Step(0.0f, 1, 1);  // finds contacts and their manifolds; dt = 0 moves nothing
  const float limit = static_cast<float>(-tolerance * sc.u);
  for (b2Contact* c = sc.world->GetContactList(); c; c = c->GetNext()) {
    if (!c->IsTouching()) continue;
    b2WorldManifold wm;
    c->GetWorldManifold(&wm);
    for (int32 i = 0; i < c->GetManifold()->pointCount; ++i)
      if (wm.separations[i] < limit) return true;
  }
  return false;
}

double bare_box2d_seconds(const WorldConfig& config, int episodes, int steps, std::uint64_t seed) {
  validate(config);
  const auto poses = poses_of(paper_start_state(config));
  const float sub_dt = static_cast<float>(config.physics.control_dt / config.physics.substeps);
  const double u = config.physics.units_per_metre;
  const auto& scale = config.action.scale;
  const auto t0 = std::chrono::steady_clock::now();
  const WorldStorage storage = make_world_storage();
  for (int e = 0; e < episodes; ++e) {
    Scene sc(config, poses, storage.get());
    Rng rng(derive_seed(seed, static_cast<std::uint64_t>(e)));
    b2Body* cup = sc.bodies[0];
    for (int t = 0; t < steps; ++t) {
      const double ax = rng.uniform(-1.0, 1.0) * scale[0], ay = rng.uniform(-1.0, 1.0) * scale[1];
      const double aw = rng.uniform(-1.0, 1.0) * scale[2];
      b2Vec2 v = cup->GetLinearVelocity();
      v.x += static_cast<float>(ax * u);
      v.y += static_cast<float>(ay * u);
      cup->SetLinearVelocity(v);
      cup->SetAngularVelocity(cup->GetAngularVelocity() + static_cast<float>(aw));
      for (int k = 0; k < config.physics.substeps; ++k)
        sc.world->Step(sub_dt, config.physics.velocity_iterations, config.physics.position_iterations);
    }
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace dicestack
