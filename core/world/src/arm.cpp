#include <dicestack/core/arm.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

namespace dicestack {
namespace {

// Damping of the least-norm rates, m: near a stretched arm the rates stay bounded.
constexpr double kDamping = 0.05;
// Where the rest posture puts the last link's near end: this fraction of the first two links'
// reach from the shoulder.
constexpr double kComfort = 0.75;

Vec2 direction(double angle) { return {std::cos(angle), std::sin(angle)}; }

double wrap_angle(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

// How far the last link is from its rest direction for where the wrist is now (rad, wrapped):
// what the posture term in the Jacobian's null space closes.
double posture_error(const ArmConfig& arm, const std::array<double, 3>& link_angles) {
  const double rest = arm_posture(arm, arm_posture_of(arm, link_angles).joints[3]).link_angles[2];
  return wrap_angle(rest - link_angles[2]);
}

}  // namespace

ArmPosture arm_posture_of(const ArmConfig& arm, const std::array<double, 3>& link_angles) {
  ArmPosture p;
  p.link_angles = link_angles;
  p.joints[0] = arm.base;
  for (std::size_t i = 0; i < 3; ++i) {
    const Vec2 u = direction(link_angles[i]);
    p.joints[i + 1] = {p.joints[i].x + arm.link_lengths[i] * u.x, p.joints[i].y + arm.link_lengths[i] * u.y};
  }
  return p;
}

Vec2 arm_wrist_velocity(const ArmConfig& arm, const std::array<double, 3>& link_angles, const std::array<double, 3>& link_rates) {
  Vec2 v{0.0, 0.0};
  for (std::size_t i = 0; i < 3; ++i) {
    v.x -= arm.link_lengths[i] * std::sin(link_angles[i]) * link_rates[i];
    v.y += arm.link_lengths[i] * std::cos(link_angles[i]) * link_rates[i];
  }
  return v;
}

ArmPosture arm_posture(const ArmConfig& arm, Vec2 wrist) {
  const auto& l = arm.link_lengths;
  const double dx = arm.base.x - wrist.x, dy = arm.base.y - wrist.y, reach = std::hypot(dx, dy);
  const double up = reach > 1e-12 ? std::atan2(dy, dx) : 0.5 * std::numbers::pi;  // from the wrist to the shoulder
  // The last link's near end at kComfort of the first two links' reach from the shoulder (as
  // near as the last link allows): the elbow stays far from folded and from stretched. It lies
  // turned by `beta` from the wrist's line to the shoulder (law of cosines).
  const double lo = std::abs(l[0] - l[1]), hi = l[0] + l[1];
  const double want = std::clamp(kComfort * hi, std::abs(reach - l[2]), reach + l[2]);
  const double cb = reach > 1e-12 ? (reach * reach + l[2] * l[2] - want * want) / (2.0 * reach * l[2]) : 1.0;
  const double beta = std::acos(std::clamp(cb, -1.0, 1.0));
  const double to_near = up + beta;
  const Vec2 near{wrist.x + l[2] * std::cos(to_near), wrist.y + l[2] * std::sin(to_near)};
  const double last = to_near + std::numbers::pi;  // the last link points from its near end to the wrist
  const double nx = near.x - arm.base.x, ny = near.y - arm.base.y, d = std::hypot(nx, ny);
  const double towards = d > 1e-12 ? std::atan2(ny, nx) : last;
  const double clamped = std::clamp(d, lo, hi);
  // Law of cosines: the shoulder link turns from the line to the near end by `bend`.
  const double c = (l[0] * l[0] + clamped * clamped - l[1] * l[1]) / (2.0 * l[0] * std::max(clamped, 1e-12));
  const double bend = std::acos(std::clamp(c, -1.0, 1.0));
  const double a0 = towards - bend;
  const Vec2 elbow{arm.base.x + l[0] * std::cos(a0), arm.base.y + l[0] * std::sin(a0)};
  const double a1 = std::atan2(near.y - elbow.y, near.x - elbow.x);
  ArmPosture p = arm_posture_of(arm, {a0, a1, wrap_angle(last)});
  p.reached = d >= lo - 1e-9 && d <= hi + 1e-9;
  return p;
}

std::array<double, 3> arm_link_rates(const ArmConfig& arm, const std::array<double, 3>& link_angles, Vec2 velocity) {
  // The wrist moves by L_i (-sin a_i, cos a_i) per unit rate of link i: J is 2 x 3.
  std::array<double, 3> jx{}, jy{};
  for (std::size_t i = 0; i < 3; ++i) {
    jx[i] = -arm.link_lengths[i] * std::sin(link_angles[i]);
    jy[i] = arm.link_lengths[i] * std::cos(link_angles[i]);
  }
  // Damped least norm: J^T (J J^T + k^2 I)^-1 v.
  double a = kDamping * kDamping, b = 0.0, d = kDamping * kDamping;
  for (std::size_t i = 0; i < 3; ++i) {
    a += jx[i] * jx[i];
    b += jx[i] * jy[i];
    d += jy[i] * jy[i];
  }
  const double det = a * d - b * b;
  const double sx = (d * velocity.x - b * velocity.y) / det, sy = (a * velocity.y - b * velocity.x) / det;
  std::array<double, 3> rates{};
  for (std::size_t i = 0; i < 3; ++i) rates[i] = jx[i] * sx + jy[i] * sy;
  // The null space of J: the cross product of its rows. Moving along it leaves the wrist where
  // it is; it turns the last link towards its rest direction.
  const std::array<double, 3> n{jx[1] * jy[2] - jx[2] * jy[1], jx[2] * jy[0] - jx[0] * jy[2], jx[0] * jy[1] - jx[1] * jy[0]};
  if (std::abs(n[2]) > 1e-6) {
    const double step = arm.posture_gain * posture_error(arm, link_angles) / n[2];
    for (std::size_t i = 0; i < 3; ++i) rates[i] += step * n[i];
  }
  return rates;
}

namespace {

using Vec4 = Eigen::Vector4d;

// The chain's mass matrix on the absolute angles, and what its centripetal terms and gravity ask
// of the angles' forces.
struct ChainDynamics {
  Eigen::Matrix4d m;
  Vec4 bias;
};

// The sines and cosines of the chain's absolute angles, taken once per law: each is read by
// every body after it, the task's Jacobian and the drift (the law runs at every substep).
struct AngleTrig {
  std::array<double, 4> sin{}, cos{};
};

AngleTrig trig_of(const std::array<double, 4>& angles) {
  AngleTrig t;
  for (std::size_t j = 0; j < 4; ++j) {
    t.sin[j] = std::sin(angles[j]);
    t.cos[j] = std::cos(angles[j]);
  }
  return t;
}

ChainDynamics chain_dynamics(const ArmConfig& arm, const ArmMotion& now, const AngleTrig& trig, Vec2 gravity) {
  const auto& w = now.rates;
  // Each body's centre and its derivative by each angle: a link's centre lies half its length
  // along it from its near joint; the cup's centre is the wrist, at the last link's far end.
  std::array<double, 4> mass{arm.link_masses[0], arm.link_masses[1], arm.link_masses[2], now.cup_mass};
  std::array<double, 4> inertia{}, along{};
  for (std::size_t i = 0; i < 3; ++i) {
    inertia[i] = arm.link_masses[i] * arm.link_lengths[i] * arm.link_lengths[i] / 12.0;
    along[i] = 0.5 * arm.link_lengths[i];
  }
  inertia[3] = now.cup_inertia;
  // dp_i/da_j = reach_ij * (-sin a_j, cos a_j); the centripetal acceleration of p_i is
  // -sum_j reach_ij * (cos a_j, sin a_j) * w_j^2.
  const auto reach = [&](std::size_t i, std::size_t j) { return j < i ? arm.link_lengths[j] : j == i ? along[i] : 0.0; };
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  Vec4 bias = Vec4::Zero();
  for (std::size_t i = 0; i < 4; ++i) {
    Eigen::Matrix<double, 2, 4> jv = Eigen::Matrix<double, 2, 4>::Zero();
    Eigen::Vector2d centripetal = Eigen::Vector2d::Zero();
    for (std::size_t j = 0; j <= i; ++j) {
      const double r = reach(i, j);
      jv(0, static_cast<Eigen::Index>(j)) = -r * trig.sin[j];
      jv(1, static_cast<Eigen::Index>(j)) = r * trig.cos[j];
      centripetal -= r * w[j] * w[j] * Eigen::Vector2d(trig.cos[j], trig.sin[j]);
    }
    m += mass[i] * jv.transpose() * jv;
    m(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) += inertia[i];
    bias += mass[i] * jv.transpose() * (centripetal - Eigen::Vector2d(gravity.x, gravity.y));
  }
  return {m, bias};
}

// Generalised forces on the absolute angles as joint torques: the force on body j is its
// joint's torque less the next joint's (which acts back on it).
Vec4 joint_torques_of(const Vec4& force) {
  Vec4 torque;
  double after = 0.0;
  for (Eigen::Index j = 3; j >= 0; --j) {
    after += force(j);
    torque(j) = after;
  }
  return torque;
}

// Each torque clipped to its limit.
std::array<double, 4> clipped(const ArmConfig& arm, const Vec4& torque) {
  std::array<double, 4> out{};
  for (std::size_t j = 0; j < 4; ++j)
    out[j] = std::clamp(torque(static_cast<Eigen::Index>(j)), -arm.torque_limit[j], arm.torque_limit[j]);
  return out;
}

// The most of `extra` that `base` can take with every joint within its limit, in [0, 1]; 0 when
// `base` alone is beyond a limit.
double within_limits(const ArmConfig& arm, const Vec4& base, const Vec4& extra) {
  double share = 1.0;
  for (std::size_t j = 0; j < 4; ++j) {
    const auto i = static_cast<Eigen::Index>(j);
    const double limit = arm.torque_limit[j];
    if (std::abs(base(i)) > limit) return 0.0;
    if (base(i) + extra(i) > limit) share = std::min(share, (limit - base(i)) / extra(i));
    if (base(i) + extra(i) < -limit) share = std::min(share, (-limit - base(i)) / extra(i));
  }
  return std::max(share, 0.0);
}

// The task's Jacobian: the cup's centre (the wrist) and its angle by the chain's absolute angles.
Eigen::Matrix<double, 3, 4> task_jacobian(const ArmConfig& arm, const AngleTrig& trig) {
  Eigen::Matrix<double, 3, 4> task = Eigen::Matrix<double, 3, 4>::Zero();
  for (std::size_t j = 0; j < 3; ++j) {
    task(0, static_cast<Eigen::Index>(j)) = -arm.link_lengths[j] * trig.sin[j];
    task(1, static_cast<Eigen::Index>(j)) = arm.link_lengths[j] * trig.cos[j];
  }
  task(2, 3) = 1.0;
  return task;
}

// The damped least-norm inverse of `task`.
Eigen::Matrix<double, 4, 3> task_inverse(const Eigen::Matrix<double, 3, 4>& task) {
  const Eigen::Matrix3d tt = task * task.transpose() + kDamping * kDamping * Eigen::Matrix3d::Identity();
  return task.transpose() * tt.inverse();
}

// Operational-space control's parts at `now`: the chain's dynamics, the task's damped inverse,
// the posture's acceleration in the task's null space, and what the task's acceleration is
// measured against (the cup's own rates, and the chain's centripetal drift).
struct OperationalSpace {
  ChainDynamics d;
  Eigen::Matrix<double, 4, 3> pinv;
  Vec4 spare;
  Eigen::Vector3d cup_rate;
  Eigen::Vector3d drift;  // the task's acceleration at zero angular acceleration
  Vec4 holding;           // the joint torques that hold the arm up and move its posture
  Vec4 posture_axis;      // the task's null space as a unit vector (zero when stretched straight)
};

// The null space of the task's Jacobian: the cup's angle has its own row, so the axis has no
// cup part; the three links' accelerations are the cross product of the x and y rows.
Vec4 posture_axis(const ArmConfig& arm, const std::array<double, 4>& a) {
  const auto& l = arm.link_lengths;
  const Vec4 axis(l[1] * l[2] * std::sin(a[2] - a[1]), l[0] * l[2] * std::sin(a[0] - a[2]), l[0] * l[1] * std::sin(a[1] - a[0]), 0.0);
  const double norm = axis.norm();
  return norm > 1e-9 ? Vec4(axis / norm) : Vec4::Zero();
}

OperationalSpace operational_space(const ArmConfig& arm, const ArmMotion& now, Vec2 gravity) {
  const auto& a = now.angles;
  const auto& w = now.rates;
  const AngleTrig trig = trig_of(a);
  OperationalSpace os{chain_dynamics(arm, now, trig, gravity), {}, Vec4::Zero(), {}, Eigen::Vector3d::Zero(), Vec4::Zero(), posture_axis(arm, a)};
  // The task: the cup's centre (the wrist) and its angle.
  const Eigen::Matrix<double, 3, 4> task = task_jacobian(arm, trig);
  for (std::size_t j = 0; j < 3; ++j) {
    const double l = arm.link_lengths[j];
    os.drift(0) -= l * w[j] * w[j] * trig.cos[j];
    os.drift(1) -= l * w[j] * w[j] * trig.sin[j];
  }
  // The cup's own velocity, not the links' rates through the chain: what the joints let drift
  // is corrected too.
  os.cup_rate = Eigen::Vector3d(now.cup_velocity.x, now.cup_velocity.y, w[3]);
  os.pinv = task_inverse(task);
  Vec4 posture = Vec4::Zero();  // critically damped towards the rest direction
  posture(2) = arm.posture_gain * arm.posture_gain * posture_error(arm, {a[0], a[1], a[2]}) - 2.0 * arm.posture_gain * w[2];
  os.spare = (Eigen::Matrix4d::Identity() - os.pinv * task) * posture;
  os.holding = joint_torques_of(os.d.m * os.spare + os.d.bias);
  return os;
}

}  // namespace

std::array<double, 4> arm_joint_space_torques(const ArmConfig& arm, const ArmMotion& now, const std::array<double, 4>& accel,
                                              Vec2 gravity) {
  const ChainDynamics d = chain_dynamics(arm, now, trig_of(now.angles), gravity);
  return clipped(arm, joint_torques_of(d.m * Vec4(accel[0], accel[1], accel[2], accel[3]) + d.bias));
}

std::array<double, 4> arm_torque_change(const ArmConfig& arm, const ArmMotion& now, Vec2 velocity_change, double turn_change,
                                        double dt) {
  const AngleTrig trig = trig_of(now.angles);
  const ChainDynamics d = chain_dynamics(arm, now, trig, {0.0, 0.0});
  // Joint torques to the forces on the absolute angles (each joint turns its body and the one
  // before it back), then to the cup's velocity and turn through the task's Jacobian.
  Eigen::Matrix4d forces = Eigen::Matrix4d::Identity();
  for (Eigen::Index j = 1; j < 4; ++j) forces(j - 1, j) = -1.0;
  const Eigen::Matrix<double, 3, 4> task = task_jacobian(arm, trig);
  const Eigen::Matrix<double, 3, 4> a = dt * task * d.m.inverse() * forces;
  const Eigen::Matrix3d aat = a * a.transpose() + 1e-12 * Eigen::Matrix3d::Identity();
  const Vec4 change = a.transpose() * aat.ldlt().solve(Eigen::Vector3d(velocity_change.x, velocity_change.y, turn_change));
  return {change(0), change(1), change(2), change(3)};
}

std::array<double, 4> arm_posture_axis(const ArmConfig& arm, const std::array<double, 4>& angles) {
  const Vec4 axis = posture_axis(arm, angles);
  return {axis(0), axis(1), axis(2), axis(3)};
}

std::array<double, 4> arm_torques(const ArmConfig& arm, const ArmMotion& now, Vec2 velocity, double angular_velocity,
                                  double dt, Vec2 gravity, double posture) {
  const auto& w = now.rates;
  const OperationalSpace os = operational_space(arm, now, gravity);
  const Eigen::Vector3d wanted = (Eigen::Vector3d(velocity.x, velocity.y, angular_velocity) - os.cup_rate) / dt - os.drift;
  // Damped least-norm angular accelerations for the task, plus the posture's in its null space.
  Vec4 accel = os.pinv * wanted + os.spare + posture * os.posture_axis;
  // No joint faster than its speed limit by the end of the substep: the relative rates it would
  // reach, clipped, give back the accelerations.
  std::array<double, 4> next{}, relative{};
  for (std::size_t i = 0; i < 4; ++i) next[i] = w[i] + accel(static_cast<Eigen::Index>(i)) * dt;
  for (std::size_t i = 0; i < 4; ++i)
    relative[i] = std::clamp(next[i] - (i > 0 ? next[i - 1] : 0.0), -arm.speed_limit[i], arm.speed_limit[i]);
  double absolute = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    absolute += relative[i];
    accel(static_cast<Eigen::Index>(i)) = (absolute - w[i]) / dt;
  }
  // Saturation: the task's share (its acceleration with the drift's correction, as the speed
  // limit left it) is scaled down as a whole, keeping what holds the arm up and moves its
  // posture; clipping each joint alone turned the excess into motion of the spare degree of
  // freedom and sent the cup elsewhere than asked.
  const Vec4 task_part = joint_torques_of(os.d.m * (accel - os.spare));
  return clipped(arm, os.holding + within_limits(arm, os.holding, task_part) * task_part);
}

LawRequest arm_torques_inverse(const ArmConfig& arm, const ArmMotion& now, const std::array<double, 4>& torques, double dt,
                               Vec2 gravity) {
  const OperationalSpace os = operational_space(arm, now, gravity);
  // Where no limit binds, torques = holding + (the task's wanted acceleration through the damped
  // inverse, and the posture's along its axis, through the mass matrix as joint torques): linear
  // in the four. The posture's column is zero where the arm is stretched straight, and the
  // posture asked is then zero.
  Eigen::Matrix4d per_asked;
  for (Eigen::Index k = 0; k < 3; ++k) per_asked.col(k) = joint_torques_of(os.d.m * os.pinv.col(k));
  per_asked.col(3) = joint_torques_of(os.d.m * os.posture_axis);
  const Vec4 beyond = Vec4(torques[0], torques[1], torques[2], torques[3]) - os.holding;
  const Vec4 asked = per_asked.colPivHouseholderQr().solve(beyond);
  const Eigen::Vector3d v = os.cup_rate + dt * (asked.head<3>() + os.drift);
  return {{{v(0), v(1)}, v(2)}, asked(3)};
}

}  // namespace dicestack
