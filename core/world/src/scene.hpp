#pragma once
// The Box2D scene of a World, shared by world.cpp (the World), snapshot.cpp (exact snapshots)
// and bare_box2d.cpp (the benchmark's bare loop), so that all three build the same bodies.
// Private to core/world: Box2D types never leave it (STYLE 9).
#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include <box2d/box2d.h>

#include <dicestack/core/types.hpp>
#include <dicestack/core/world.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack::detail {

constexpr int kWallFixtures = 4, kCupFixtures = 3, kFixtureCount = kWallFixtures + kCupFixtures + 3;
constexpr int kBodies = 4;  // cup, die 0, die 1, die 2 (the static walls carry no state)

// Fixture ids, stored as user data (id + 1, so that 0 means "not ours").
constexpr int kFirstCupFixture = kWallFixtures, kFirstDieFixture = kWallFixtures + kCupFixtures;

// The arm's links come after the dice, one fixture each.
constexpr int kFirstLinkFixture = kFixtureCount, kArmLinks = 3, kArmJoints = 4;

inline ShapeKind kind_of_fixture(int id) {
  if (id < kWallFixtures) return static_cast<ShapeKind>(id);
  if (id >= kFirstLinkFixture) return ShapeKind::arm;
  return id < kFirstDieFixture ? ShapeKind::cup : ShapeKind::die;
}

inline int fixture_id(b2Fixture* f) { return static_cast<int>(f->GetUserData().pointer) - 1; }

inline bool is_side_wall_or_ceiling(int id) { return id >= 1 && id < kWallFixtures; }

struct Pose {
  double x = 0, y = 0, angle = 0, vx = 0, vy = 0, w = 0;
};

/// The cup and dice poses of a state, in body order.
std::array<Pose, kBodies> poses_of(const State& s);

// Memory for one b2World. The object holds Box2D's 100 KB stack allocator inline; rebuilding
// a scene in the same block avoids a large allocation per reset (measured: 70 us -> 3 us).
using WorldStorage = std::unique_ptr<std::byte[]>;
WorldStorage make_world_storage();

// The scene in Box2D units, built the same way for World and for the bare benchmark loop.
struct Scene {
  double u = 10.0;  // Box2D units per metre
  b2World* world = nullptr;               // constructed in caller-owned storage
  std::array<b2Body*, kBodies> bodies{};  // cup, dice
  std::array<b2Fixture*, kFixtureCount> fixtures{};
  // The arm (empty for the floating cup): links from the shoulder, their fixtures (ids from
  // kFirstLinkFixture), and the shoulder, elbow, second elbow and wrist joints.
  std::vector<b2Body*> links;
  std::vector<b2Fixture*> link_fixtures;
  std::vector<b2RevoluteJoint*> joints;

  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;
  ~Scene() { world->~b2World(); }

  /// The scene at `poses`; an arm in the rest posture for the cup's pose, or, given `encoders`, in
  /// the links its encoders read, with the cup where they hold it (its angle and turn rate from
  /// `poses`).
  Scene(const WorldConfig& c, const std::array<Pose, kBodies>& poses, std::byte* storage, const ArmLinks* encoders = nullptr);

  b2ContactManager& contacts() const { return const_cast<b2ContactManager&>(world->GetContactManager()); }
  /// Every fixture by id: walls, cup, dice, then the arm's links.
  int fixture_count() const { return kFixtureCount + static_cast<int>(link_fixtures.size()); }
  b2Fixture* fixture(int id) const {
    return id < kFixtureCount ? fixtures[static_cast<std::size_t>(id)] : link_fixtures[static_cast<std::size_t>(id - kFixtureCount)];
  }
  /// The links' absolute directions (rad), from their bodies.
  std::array<double, 3> link_angles() const;
  /// The links' absolute rates (rad/s).
  std::array<double, 3> link_rates() const;
  /// Applies, for the next substep of `dt`, the joint torques that bring the cup's velocity to
  /// `target` (m/s, m/s, rad/s; arm_torques); they are kept in `torques`.
  void drive_arm(const ArmConfig& arm, const Action& target, double dt, Vec2 gravity);
  /// Applies, for the next substep, the joint torques `wanted` (N m, shoulder first) as the
  /// arm's drives give them: each clipped to its limit, and none while its joint already turns
  /// at its speed limit in the torque's direction. They are kept in `torques`.
  void hold_joint_torques(const ArmConfig& arm, const std::array<double, 4>& wanted);
  std::array<double, 4> torques{};  // the arm's joint torques in the last substep, N m
  std::array<double, 4> torque_sum{};  // summed over the substeps of the step under way, N m

 private:
  void apply_joint_torques();  // `torques`, each on its body and back on the body before it
};

}  // namespace dicestack::detail
