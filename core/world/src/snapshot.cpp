// WorldSnapshot: what an exact snapshot holds, its byte record, and World::snapshot/restore.
// The only translation unit that reaches into Box2D's private members (box2d_access.hpp).
#include <dicestack/core/world.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "box2d_access.hpp"
#include "byte_io.hpp"
#include "scene.hpp"
#include "world_impl.hpp"
#include <dicestack/core/error.hpp>

namespace dicestack {

using detail::get;
using detail::fixture_id;
using detail::kBodies;
using detail::kFixtureCount;
using detail::poses_of;
using detail::Scene;

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
  // A joint's warm-starting impulses (the rest of it is rebuilt from its bodies each step).
  struct Joint {
    b2Vec2 impulse;
    float motor_impulse, lower_impulse, upper_impulse;
  };
  State state{};
  std::vector<Body> bodies;    // cup, dice, then the arm's links
  std::vector<Joint> joints;  // the arm's, shoulder first
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
// 1: the cup and the dice. 2: adds the arm's links and joints (none for the floating cup).
constexpr std::uint32_t kSnapshotVersion = 2;
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

// Reads one body's transform, sweep, velocities, flags and sleep time.
void read_snapshot_body(detail::ByteReader& r, WorldSnapshot::Data::Body& b) {
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

// Reads broad-phase node i of a tree of `capacity` nodes into `n`; returns its leaf flag.
bool read_broad_phase_node(detail::ByteReader& r, b2TreeNode& n, int32 i, int32 capacity) {
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
  const auto check_index = [&](int32 index, std::string_view field) {
    if (index < b2_nullNode || index >= capacity)
      r.fail(std::string(field) + " of broad-phase node " + std::to_string(i) + " is " + std::to_string(index) +
             ", outside [-1, " + std::to_string(capacity - 1) + "]");
  };
  check_index(n.parent, "parent");
  if (n.height < 0) return leaf;
  if (moved > 1) r.fail("broad-phase node " + std::to_string(i) + " has a flag that is not 0 or 1");
  check_index(n.child1, "child");
  check_index(n.child2, "child");
  for (float v : {n.aabb.lowerBound.x, n.aabb.lowerBound.y, n.aabb.upperBound.x, n.aabb.upperBound.y})
    if (!std::isfinite(v)) r.fail("broad-phase node " + std::to_string(i) + " has a box that is not finite");
  return leaf;
}

// Reads the broad-phase tree: its nodes, root, node count, free list, insertions and move buffer.
void read_broad_phase(detail::ByteReader& r, WorldSnapshot::Data& d) {
  const int32 capacity = r.get_in<std::int32_t>(1, kMaxTreeNodes, "broad-phase capacity");
  const auto node_index = [&](std::string_view field) { return r.get_in<std::int32_t>(b2_nullNode, capacity - 1, field); };
  d.tree_nodes.resize(static_cast<std::size_t>(capacity));
  d.tree_leaf.resize(static_cast<std::size_t>(capacity));
  for (int32 i = 0; i < capacity; ++i) {
    const auto at = static_cast<std::size_t>(i);
    d.tree_leaf[at] = read_broad_phase_node(r, d.tree_nodes[at], i, capacity);
  }
  d.tree_root = node_index("broad-phase root");
  d.tree_node_count = r.get_in<std::int32_t>(0, capacity, "broad-phase node count");
  d.tree_free_list = node_index("broad-phase free list");
  d.tree_insertions = r.get_in<std::int32_t>(0, std::numeric_limits<std::int32_t>::max(), "broad-phase insertions");
  const auto moves = r.get_in<std::int32_t>(0, capacity, "broad-phase move count");
  for (std::int32_t i = 0; i < moves; ++i) d.move_buffer.push_back(node_index("broad-phase move"));
}

// Reads one contact: its fixtures and children, flags, manifold and time of impact.
WorldSnapshot::Data::Contact read_snapshot_contact(detail::ByteReader& r, int fixtures) {
  WorldSnapshot::Data::Contact c{};
  c.fixture_a = r.get_in<std::int32_t>(0, fixtures - 1, "contact fixture");
  c.fixture_b = r.get_in<std::int32_t>(0, fixtures - 1, "contact fixture");
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
  return c;
}

}  // namespace

std::string WorldSnapshot::to_bytes() const {
  if (!data_) throw InputError("world snapshot: an empty (default-constructed) snapshot has no bytes");
  const Data& d = *data_;
  detail::ByteWriter w;
  w.put(kSnapshotMarker);
  w.put(kSnapshotVersion);
  for (double v : d.state) w.put(v);
  w.put(static_cast<std::int32_t>(d.bodies.size() - kBodies));
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
  for (const auto& j : d.joints) {
    put_vec(w, j.impulse);
    w.put(j.motor_impulse);
    w.put(j.lower_impulse);
    w.put(j.upper_impulse);
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
  if (version < 1 || version > kSnapshotVersion)
    r.fail("version " + std::to_string(version) + ", this dicestack reads 1 to " + std::to_string(kSnapshotVersion));
  auto d = std::make_shared<Data>();
  for (double& v : d->state) v = r.get_finite<double>("state");
  const int links = version >= 2 ? r.get_in<std::int32_t>(0, detail::kArmLinks, "arm link count") : 0;
  if (links != 0 && links != detail::kArmLinks) r.fail("an arm of " + std::to_string(links) + " links");
  d->bodies.resize(static_cast<std::size_t>(kBodies + links));
  for (auto& b : d->bodies) read_snapshot_body(r, b);
  d->joints.resize(links == 0 ? 0 : detail::kArmJoints);
  for (auto& j : d->joints) {
    j.impulse = get_vec(r, "joint impulse");
    j.motor_impulse = r.get_finite<float>("joint impulse");
    j.lower_impulse = r.get_finite<float>("joint impulse");
    j.upper_impulse = r.get_finite<float>("joint impulse");
  }
  read_broad_phase(r, *d);
  const int fixtures = kFixtureCount + links;
  const auto contacts = r.get_in<std::int32_t>(0, fixtures * fixtures, "contact count");
  for (std::int32_t i = 0; i < contacts; ++i) d->contacts.push_back(read_snapshot_contact(r, fixtures));
  d->inv_dt0 = r.get_finite<float>("inverse time step");
  d->new_contacts = r.get_in<std::uint8_t>(0, 1, "world flag") != 0;
  d->step_complete = r.get_in<std::uint8_t>(0, 1, "world flag") != 0;
  r.expect_end();
  WorldSnapshot snap;
  snap.data_ = std::move(d);
  return snap;
}

WorldSnapshot World::snapshot() const {
  const Scene& sc = *impl_->scene;
  auto data = std::make_shared<WorldSnapshot::Data>();
  data->state = impl_->state();
  for (std::size_t i = 0; i < kBodies + sc.links.size(); ++i) {
    b2Body& b = *(i < kBodies ? sc.bodies[i] : sc.links[i - kBodies]);
    data->bodies.push_back({get<detail::BodyXf>(b), get<detail::BodySweep>(b), b.GetLinearVelocity(),
                            b.GetAngularVelocity(), get<detail::BodyFlags>(b), get<detail::BodySleepTime>(b)});
  }
  for (b2RevoluteJoint* j : sc.joints)
    data->joints.push_back({get<detail::JointImpulse>(*j), get<detail::JointMotorImpulse>(*j),
                            get<detail::JointLowerImpulse>(*j), get<detail::JointUpperImpulse>(*j)});
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
  if (d.bodies.size() != kBodies + scene->links.size())
    throw std::logic_error("world snapshot: taken with another embodiment (the arm's links differ)");
  const auto body = [&](std::size_t i) -> b2Body& { return *(i < kBodies ? scene->bodies[i] : scene->links[i - kBodies]); };
  for (std::size_t i = 0; i < d.bodies.size(); ++i) {
    b2Body& b = body(i);
    const auto& s = d.bodies[i];
    get<detail::BodyXf>(b) = s.xf;
    get<detail::BodySweep>(b) = s.sweep;
    b.SetLinearVelocity(s.velocity);
    b.SetAngularVelocity(s.angular_velocity);
  }
  for (std::size_t j = 0; j < d.joints.size(); ++j) {
    b2RevoluteJoint& joint = *scene->joints[j];
    get<detail::JointImpulse>(joint) = d.joints[j].impulse;
    get<detail::JointMotorImpulse>(joint) = d.joints[j].motor_impulse;
    get<detail::JointLowerImpulse>(joint) = d.joints[j].lower_impulse;
    get<detail::JointUpperImpulse>(joint) = d.joints[j].upper_impulse;
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
    if (it->fixture_a >= scene->fixture_count() || it->fixture_b >= scene->fixture_count())
      throw std::logic_error("world snapshot: a contact names a fixture this world does not have");
    b2Fixture* fa = scene->fixture(it->fixture_a);
    b2Fixture* fb = scene->fixture(it->fixture_b);
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
  for (std::size_t i = 0; i < d.bodies.size(); ++i) {
    get<detail::BodyFlags>(body(i)) = d.bodies[i].flags;
    get<detail::BodySleepTime>(body(i)) = d.bodies[i].sleep_time;
  }
  b2World& w = *scene->world;
  get<detail::WorldInvDt0>(w) = d.inv_dt0;
  get<detail::WorldNewContacts>(w) = d.new_contacts;
  get<detail::WorldStepComplete>(w) = d.step_complete;
}

}  // namespace dicestack
