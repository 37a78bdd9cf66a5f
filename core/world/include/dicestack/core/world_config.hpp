#pragma once
// Every constant of the dice-stacking world, with the paper's values as defaults (DESIGN "The
// world", paper III). SI units throughout; 1 m is 100 px of the original 900 x 700 px window.
#include <array>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <dicestack/core/types.hpp>
#include <dicestack/core/vec2.hpp>

namespace dicestack {

/// The enclosure: four static rounded segments (floor, left, right, ceiling).
struct WallsConfig {
  double floor_y = 0.60;    ///< floor centre line, m; the table surface is floor_y + radius = 1.00
  double left_x = 0.05;     ///< left wall centre line, m
  double right_x = 8.95;    ///< right wall centre line, m
  double ceiling_y = 6.95;  ///< ceiling centre line, m
  double radius = 0.40;     ///< segment radius, m, > 0
  double friction = 1.0;    ///< Coulomb coefficient, >= 0 (paper eq. 3)
  bool operator==(const WallsConfig&) const = default;
};

/// The cup: three rounded segments on one rigid body, mouth up at angle 0 (paper III).
struct CupConfig {
  double base_width = 1.00;    ///< base segment length, m
  double wall_height = 2.20;   ///< vertical rise of each side wall, m
  double flare = 0.20;         ///< outward offset of each wall's top (the cup's outward tilt), m
  double radius = 0.05;        ///< segment radius, m
  double segment_mass = 5.0;   ///< kg per segment
  double friction = 0.4;       ///< paper eq. 4
  Vec2 start_anchor{4.00, 1.90};          ///< left end of the base before the start rotation, m
  double start_angle = std::numbers::pi;  ///< rotation about the centre of mass at the start
  bool operator==(const CupConfig&) const = default;
};

/// The three dice: octagons, squares with cut corners (paper III).
struct DiceConfig {
  double half_size = 0.20;   ///< half the side of the square, m
  double corner_cut = 0.05;  ///< length cut off each corner along both sides, m, < half_size
  double mass = 1.0;         ///< kg (the original's value; the paper's text says 10 g)
  double friction = 0.6;     ///< paper eq. 2
  std::array<double, kDiceCount> start_x{4.08, 4.51, 4.93};  ///< m
  double start_y = 1.25;     ///< m; the dice start 5 cm above the table and drop
  bool operator==(const DiceConfig&) const = default;
};

/// What moves the cup: the paper's floating cup (each action adds to its velocity directly) or a
/// planar arm holding it (the action is turned into joint motions under torque limits).
enum class Embodiment { cup, arm };

/// The planar arm of the paper's future work: three links and a wrist, four revolute joints,
/// the cup's centre of mass held by the wrist. The arm moves in a plane in front of the scene:
/// its links meet the walls, the table and the ceiling, not the dice or the cup. Joint angles
/// are relative (a link's angle minus the previous one's; the shoulder's is absolute, the
/// wrist's is the cup's angle minus the last link's).
struct ArmConfig {
  Vec2 base{4.50, 6.20};  ///< the shoulder joint, fixed to the ceiling's mount, m
  std::array<double, 3> link_lengths{2.40, 2.40, 1.60};  ///< m
  std::array<double, 3> link_masses{6.0, 4.0, 3.0};      ///< kg (the cup is 15 kg: Box2D wants ratios under 10)
  double link_radius = 0.06;  ///< m
  std::array<double, 4> joint_lower{-6.3, -2.9, -2.9, -12.6};  ///< rad
  std::array<double, 4> joint_upper{6.3, 2.9, 2.9, 12.6};      ///< rad
  /// N m per joint: the 99th percentile of what the human recordings' cup paths ask of each joint
  /// (`dicestack bench arm`, docs/arm.md).
  std::array<double, 4> torque_limit{7500.0, 6500.0, 1700.0, 700.0};
  std::array<double, 4> speed_limit{20.0, 20.0, 20.0, 20.0};  ///< rad/s per joint
  /// Rate (1/s) at which the spare degree of freedom is pulled back to the rest posture
  /// (arm_posture in arm.hpp).
  double posture_gain = 5.0;
  bool operator==(const ArmConfig&) const = default;
};

/// Integration and simulation settings.
struct PhysicsConfig {
  Vec2 gravity{0.0, -4.0};        ///< m/s^2 (paper eq. 1)
  double control_dt = 1.0 / 30.0; ///< one control step (one action), s
  int substeps = 5;               ///< physics steps per control step
  int velocity_iterations = 10;   ///< solver iterations per substep (paper III)
  int position_iterations = 3;    ///< Box2D's position correction passes per substep
  bool allow_sleep = false;       ///< let resting bodies sleep (faster; see docs/world.md)
  double units_per_metre = 10.0;  ///< internal Box2D length scale; keeps its 0.01-unit skin at 1 mm
  double action_noise = 0.0;      ///< std of Gaussian noise added to each action, as a fraction of
                                  ///< ActionConfig::scale; 0 is deterministic (paper III non-determinism)
  bool operator==(const PhysicsConfig&) const = default;
};

/// Action scaling and limits.
struct ActionConfig {
  /// What x = 1 means for optimisers working on [-1, 1]^3 (paper V-B: 100, 10, 0.5 px units).
  std::array<double, kActionDim> scale{1.0, 0.1, 0.5};
  /// Largest |dv| the environment accepts per step; larger actions are clipped (m/s, m/s, rad/s).
  /// Human recordings reach 17 m/s with the stopping mechanic.
  std::array<double, kActionDim> limit{20.0, 20.0, 10.0};
  bool operator==(const ActionConfig&) const = default;
};

/// Randomised initial states for reset(seed). All zero gives the paper's start.
struct RandomizationConfig {
  double shift = 0.5;        ///< the whole scene (cup and dice) shifts by U(-shift, shift) in x, m
  double die_jitter = 0.01;  ///< each die moves by U(-j, j) in x, m
  double cup_lift = 0.2;     ///< the cup starts U(0, lift) higher, m
  double cup_tilt = 0.05;    ///< the cup's start angle changes by U(-tilt, tilt), rad
  bool die_quarter_turns = true;  ///< each die starts rotated by a random multiple of 90 degrees
  bool operator==(const RandomizationConfig&) const = default;
};

/// Tolerances of the outcome judge (DESIGN "Outcome judge").
struct JudgeConfig {
  double column_tolerance = 0.10;  ///< max |x| offset between a die and the one below it, m
  double gap_tolerance = 0.04;     ///< max deviation of centre spacing from one die side, m
  double angle_tolerance = 0.15;   ///< max deviation of a die from a multiple of 90 degrees, rad
  double rest_speed = 0.05;        ///< max die speed at rest, m/s
  double rest_angular_speed = 0.2; ///< max die angular speed at rest, rad/s
  double wall_contact_distance = 0.002;  ///< a gap at most this wide counts as touching, m
  int success_hold_steps = 5;      ///< a realistic success must hold this many control steps
  bool operator==(const JudgeConfig&) const = default;
};

/// Episode limits.
struct EpisodeConfig {
  int max_steps = 400;  ///< time limit in control steps (truncated after it)
  bool operator==(const EpisodeConfig&) const = default;
};

/// The optimisers' cost (paper eq. 6) and the environment's reward.
struct CostConfig {
  double gamma = 0.1;    ///< discount in [0, 1]; weight of step j is gamma^(T - j)
  double goal_x = 4.51;  ///< x of the goal stack, m (the middle die's start)
  /// Per-dimension scale of the L2 state distance (population std of the 68 human recordings,
  /// converted to SI; see docs/world.md).
  State sigma{};
  bool operator==(const CostConfig&) const = default;
};

/// Everything that defines a world. Plain data; validate() checks it.
struct WorldConfig {
  WallsConfig walls;
  CupConfig cup;
  DiceConfig dice;
  PhysicsConfig physics;
  ActionConfig action;
  RandomizationConfig randomization;
  JudgeConfig judge;
  EpisodeConfig episode;
  CostConfig cost = default_cost();
  Embodiment embodiment = Embodiment::cup;
  ArmConfig arm;  ///< read only with embodiment arm

  /// The cost defaults, with the measured per-dimension sigma.
  static CostConfig default_cost();
  bool operator==(const WorldConfig&) const = default;
};

/// The largest |value| an environment passes on, per component of an action of `kind`:
/// action.limit for the cup, arm.torque_limit for joint torques. Refers into `config`.
std::span<const double> action_limit(const WorldConfig& config, ActionKind kind);
/// `action` with each component clipped to action_limit(config, action.kind()).
Action clipped(const WorldConfig& config, Action action);
/// One unit of a component of an action of `kind`, what action noise is a fraction of:
/// action.scale for the cup, arm.torque_limit for joint torques. Refers into `config`.
std::span<const double> action_scale(const WorldConfig& config, ActionKind kind);

/// Throws ConfigError naming the first field that is out of range, e.g.
/// `world config: field "physics.substeps" must be >= 1, got 0`, or whose start does not fit:
/// dice and cup inside the walls and the dice apart at every shift, jitter, lift and tilt.
void validate(const WorldConfig& config);

/// Parses JSON text; every field must be present, of the right type, finite and in range, and
/// the start must fit inside the walls. Reads format versions 1 (no marker), 2 ("format":
/// "dicestack-world", "version": 2) and 3 (adds "embodiment" and "arm"; older files are the
/// floating cup); docs/formats.md. `source` names the text in messages (a
/// path, or "<string>"). Throws ConfigError.
WorldConfig world_config_from_json(std::string_view text, std::string_view source = "<string>");

/// Pretty-printed JSON holding the format marker, the version and every field.
std::string to_json(const WorldConfig& config);

/// FNV-1a of the fields alone (not the format version): the world's identity in cache names,
/// checkpoints and snapshots, unchanged when only the file format moves on (a floating-cup
/// world's arm fields, which it never reads, are left out).
std::uint64_t world_hash(const WorldConfig& config);

/// One field of the world config file, as its reference page lists it.
struct WorldConfigField {
  std::string path;           ///< the JSON path, e.g. "physics.substeps"
  std::string type;           ///< "number", "integer", "boolean" or "N numbers"
  std::string default_value;  ///< WorldConfig{}'s value, as JSON
  std::string range;          ///< e.g. "in [1, 1000]"; empty when any value of the type is valid
  std::string meaning;        ///< what it is, with its unit
};

/// Every field of the file, in file order: the list the reader, the writer and the range check
/// walk, so the reference page cannot miss one.
std::vector<WorldConfigField> world_config_fields();

/// Reads a JSON file; throws InputError if unreadable, ConfigError if invalid.
WorldConfig load_world_config(const std::filesystem::path& path);

/// Writes a JSON file atomically (temporary file, then rename). An existing file is replaced only
/// if it is a JSON object of world config sections; anything else is refused (InputError).
void save_world_config(const WorldConfig& config, const std::filesystem::path& path);

}  // namespace dicestack
