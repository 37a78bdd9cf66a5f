#pragma once
// The Box2D scene of the dice-stacking task and one control step of it. Box2D types never leave
// core/: everything here is SI and our own types (STYLE 9).
#include <array>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/arm.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/core/vec2.hpp>
#include <dicestack/core/world_config.hpp>

namespace dicestack {

/// An exact copy of a World's dynamic state: the 24 observed numbers and what Box2D carries
/// between steps (contact manifolds with their warm-starting impulses, the broad-phase tree,
/// solver bookkeeping). Restoring it continues bit-for-bit like the run it was taken from.
/// Cheap to copy (shared, immutable); valid for Worlds built from the same WorldConfig.
class WorldSnapshot {
 public:
  WorldSnapshot();
  ~WorldSnapshot();
  WorldSnapshot(const WorldSnapshot&);
  WorldSnapshot& operator=(const WorldSnapshot&);

  /// The observed state when the snapshot was taken.
  const State& state() const;
  /// False for a default-constructed snapshot.
  bool valid() const { return data_ != nullptr; }

  /// The snapshot as a self-checking byte record (marker, version, checksum), for pickles and
  /// files. Like the snapshot itself it is only meaningful for a World built from the same
  /// config (callers store the config's hash beside it) and the same dicestack build.
  /// Throws InputError for an empty snapshot.
  std::string to_bytes() const;
  /// Reads to_bytes()'s record, checking marker, version, checksum, sizes and every index.
  /// Throws InputError naming what is wrong.
  static WorldSnapshot from_bytes(std::string_view bytes);

  struct Data;  ///< Box2D-level contents, private to core/world/src/snapshot.cpp

 private:
  friend class World;
  std::shared_ptr<const Data> data_;
};

/// Which solid a shape belongs to, for drawing and for the outcome judge.
enum class ShapeKind { floor, left_wall, right_wall, ceiling, cup, die, arm };

/// One shape in world coordinates: a convex polygon, rounded by `radius`, in metres.
struct ShapeOutline {
  ShapeKind kind = ShapeKind::floor;
  int index = 0;  ///< segment index for the cup (0 left, 1 base, 2 right), die index for dice, link index for the arm
  std::vector<Vec2> points;
  double radius = 0.0;
};

/// The physical world: walls, the three-segment cup and three octagonal dice (DESIGN table).
/// Deterministic: the same state and actions give bit-identical results.
class World {
 public:
  /// Builds the scene at the paper's start. Throws ConfigError if `config` is invalid.
  explicit World(const WorldConfig& config);
  /// Builds the scene at `state` (see set_state).
  World(const WorldConfig& config, const State& state);
  ~World();
  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  const WorldConfig& config() const;

  /// The 24 observed numbers (SI, cup at its centre of mass).
  State state() const;

  /// Rebuilds the scene at a bare 24-number state. Contacts start without warm-starting
  /// impulses, so the continuation can differ slightly from a run that reached this state by
  /// itself (measured in docs/world.md). state() afterwards returns `state` exactly. An arm
  /// takes its rest posture (arm_posture) and the link rates that move the cup as the state says.
  /// Throws InputError if a value is not finite.
  void set_state(const State& state);
  /// The same with the arm's links as its encoders read them: the links take those angles and
  /// rates, and the cup is where they hold it (its angle, turn rate and the dice from `state`).
  /// Throws InputError for a floating cup or a value that is not finite.
  void set_state(const State& state, const ArmLinks& links);

  /// An exact snapshot of the current state; see WorldSnapshot.
  WorldSnapshot snapshot() const;

  /// Restores a snapshot taken from a World with the same config; continues bit-for-bit.
  /// Throws InputError if the snapshot is empty.
  void restore(const WorldSnapshot& snapshot);

  /// One control step. A cup action adds `dv` (m/s, m/s, rad/s) to the cup's velocity, then
  /// runs the configured substeps; with the arm, the cup controller's torques drive the cup at
  /// the velocity a floating cup would have (its velocity plus dv, then gravity's pull over the
  /// step), within the torque limits. A joint-torque action (the arm only) holds its four torques
  /// through every substep, each clipped to its limit and withheld while its joint turns at its
  /// speed limit in the torque's direction. Returns true if the cup, a die or a link touched a
  /// side wall or the ceiling during the step. Throws InputError if `dv` is not finite, or
  /// holds joint torques for a floating cup. Does not clip a cup action.
  bool step(const Action& dv);

  /// Every shape, in world coordinates, for drawing.
  std::vector<ShapeOutline> outlines() const;

  /// True if any two shapes (cup, dice, walls) overlap by more than `tolerance` metres. Used on
  /// probe worlds to reject random initial states: it builds the contacts without moving
  /// anything, which a run that continues from here would do in its first step anyway.
  bool has_overlaps(double tolerance = 0.005);
  /// The first overlap deeper than `tolerance`, named ("die 1 and die 2 overlap by 0.150 m",
  /// "the cup and the walls ..."), or empty. Like has_overlaps, for probe worlds.
  std::string first_overlap(double tolerance = 0.005);

  /// The arm's link directions now (absolute, rad); zeros for the floating cup.
  std::array<double, 3> arm_link_angles() const;
  /// The arm's link rates now (absolute, rad/s); zeros for the floating cup.
  std::array<double, 3> arm_link_rates() const;
  /// Both, as a policy's joint encoders read them (zeros for the floating cup).
  ArmLinks arm_links() const { return {arm_link_angles(), arm_link_rates()}; }
  /// The arm and the cup as one chain now (arm.hpp's ArmMotion: the links' and the cup's angles
  /// and rates, the cup's velocity, mass and inertia), for joint-space control.
  ArmMotion arm_motion() const;
  /// The torque each joint's motor gave in the last substep, N m; zeros for the floating cup.
  std::array<double, 4> arm_joint_torques() const;
  /// The joint torques averaged over the last step's substeps, N m: held through a step, they
  /// give the joints the angular impulse the step gave them (how a cup action is told in
  /// joint torques). Zeros for the floating cup.
  std::array<double, 4> arm_step_torques() const;

  /// True if the cup or a die is within judge.wall_contact_distance of a side wall or the
  /// ceiling now. Like has_overlaps, for probe worlds (e.g. judging recorded states).
  bool touching_walls();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Throws InputError naming the body unless `state` is one a world can hold: every body's centre
/// inside the walls and above the table, and no two shapes (cup, dice, walls) overlapping by more
/// than 5 mm. For states a user starts from (reset to a given state); `what` prefixes the message.
void check_state_in_world(const State& state, const WorldConfig& config, std::string_view what);

}  // namespace dicestack
