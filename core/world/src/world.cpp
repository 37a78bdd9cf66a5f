#include <dicestack/core/world.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "scene.hpp"
#include "world_impl.hpp"
#include <dicestack/core/error.hpp>
#include <dicestack/core/geometry.hpp>
#include <dicestack/core/initial_state.hpp>

namespace dicestack {

using detail::kFirstCupFixture;
using detail::kFirstDieFixture;
using detail::kind_of_fixture;
using detail::poses_of;
using detail::Scene;

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

void World::set_state(const State& state, const ArmLinks& links) {
  if (impl_->config.embodiment != Embodiment::arm) throw InputError("world state: arm links given to a floating cup");
  require_finite(state, "world state");
  for (std::size_t i = 0; i < 3; ++i)
    if (!std::isfinite(links.angles[i]) || !std::isfinite(links.rates[i])) throw InputError("world state: an arm link is not finite");
  impl_->rebuild(poses_of(state), &links);
}

bool World::step(const Action& dv) {
  require_finite(dv, "action");
  Scene& sc = *impl_->scene;
  const WorldConfig& c = impl_->config;
  b2Body* cup = sc.bodies[0];
  const int vel_it = c.physics.velocity_iterations, pos_it = c.physics.position_iterations;
  bool wall = false;
  sc.torque_sum = {};
  if (dv.kind() == ActionKind::joint_torque) {
    if (c.embodiment != Embodiment::arm)
      throw InputError("action: joint torques need a world whose embodiment is \"arm\"; in this one the cup floats");
    const std::array<double, 4> wanted{dv[0], dv[1], dv[2], dv[3]};
    for (int k = 0; k < c.physics.substeps; ++k) {
      sc.hold_joint_torques(c.arm, wanted);  // Box2D clears applied torques after each step
      sc.world->Step(impl_->sub_dt, vel_it, pos_it);
      wall = wall || impl_->touches_wall();
    }
    return wall;
  }
  if (c.embodiment == Embodiment::arm) {
    // The velocity a floating cup would have after each substep: its own plus dv, then
    // gravity's pull; the arm's torques drive it there (the dice push it less than they push a
    // floating cup: the arm holds it).
    const b2Vec2 v = cup->GetLinearVelocity();
    const Action start{v.x / sc.u + dv[0], v.y / sc.u + dv[1], cup->GetAngularVelocity() + dv[2]};
    for (int k = 0; k < c.physics.substeps; ++k) {
      const double t = (k + 1) * static_cast<double>(impl_->sub_dt);
      const Action target{start[0] + c.physics.gravity.x * t, start[1] + c.physics.gravity.y * t, start[2]};
      sc.drive_arm(c.arm, target, impl_->sub_dt, c.physics.gravity);
      sc.world->Step(impl_->sub_dt, vel_it, pos_it);
      wall = wall || impl_->touches_wall();
    }
    return wall;
  }
  b2Vec2 v = cup->GetLinearVelocity();
  v.x += static_cast<float>(dv[0] * sc.u);
  v.y += static_cast<float>(dv[1] * sc.u);
  cup->SetLinearVelocity(v);
  cup->SetAngularVelocity(cup->GetAngularVelocity() + static_cast<float>(dv[2]));
  for (int k = 0; k < c.physics.substeps; ++k) {
    sc.world->Step(impl_->sub_dt, vel_it, pos_it);
    wall = wall || impl_->touches_wall();
  }
  return wall;
}

std::array<double, 3> World::arm_link_angles() const { return impl_->scene->link_angles(); }

std::array<double, 3> World::arm_link_rates() const { return impl_->scene->link_rates(); }

std::array<double, 4> World::arm_joint_torques() const { return impl_->scene->torques; }

ArmMotion World::arm_motion() const {
  const auto links = arm_link_angles();
  const auto rates = arm_link_rates();
  const State s = state();
  const CupGeometry cup = cup_geometry(impl_->config.cup);
  ArmMotion m;
  m.angles = {links[0], links[1], links[2], s[state_index::kCupAngle]};
  m.rates = {rates[0], rates[1], rates[2], s[state_index::kCupW]};
  m.cup_velocity = {s[state_index::kCupVx], s[state_index::kCupVy]};
  m.cup_mass = cup.mass;
  m.cup_inertia = cup.inertia;
  return m;
}

std::array<double, 4> World::arm_step_torques() const {
  std::array<double, 4> mean = impl_->scene->torque_sum;
  for (double& t : mean) t /= impl_->config.physics.substeps;
  return mean;
}

std::vector<ShapeOutline> World::outlines() const {
  const Scene& sc = *impl_->scene;
  std::vector<ShapeOutline> out;
  for (int id = 0; id < sc.fixture_count(); ++id) {
    const b2Fixture* f = sc.fixture(id);
    const auto* poly = static_cast<const b2PolygonShape*>(f->GetShape());
    const b2Transform& xf = f->GetBody()->GetTransform();
    ShapeOutline o;
    o.kind = kind_of_fixture(id);
    o.index = o.kind == ShapeKind::cup   ? id - kFirstCupFixture
              : o.kind == ShapeKind::die ? id - kFirstDieFixture
              : o.kind == ShapeKind::arm ? id - detail::kFirstLinkFixture
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

std::string World::first_overlap(double tolerance) {
  Scene& sc = *impl_->scene;
  sc.world->Step(0.0f, 1, 1);  // finds contacts and their manifolds; dt = 0 moves nothing
  const float limit = static_cast<float>(-tolerance * sc.u);
  auto name = [&](const b2Body* b) -> std::string {
    for (std::size_t i = 0; i < sc.bodies.size(); ++i)
      if (sc.bodies[i] == b) return i == 0 ? "the cup" : "die " + std::to_string(i - 1);
    for (std::size_t i = 0; i < sc.links.size(); ++i)
      if (sc.links[i] == b) return "arm link " + std::to_string(i);
    return "the walls";
  };
  for (b2Contact* c = sc.world->GetContactList(); c; c = c->GetNext()) {
    if (!c->IsTouching()) continue;
    b2WorldManifold wm;
    c->GetWorldManifold(&wm);
    float deepest = 0.0f;
    for (int32 i = 0; i < c->GetManifold()->pointCount; ++i) deepest = std::min(deepest, wm.separations[i]);
    if (deepest < limit) {
      char text[160];
      std::snprintf(text, sizeof text, "%s and %s overlap by %.3f m", name(c->GetFixtureA()->GetBody()).c_str(),
                    name(c->GetFixtureB()->GetBody()).c_str(), -static_cast<double>(deepest) / sc.u);
      return text;
    }
  }
  return {};
}

bool World::has_overlaps(double tolerance) { return !first_overlap(tolerance).empty(); }

void check_state_in_world(const State& state, const WorldConfig& config, std::string_view what) {
  require_finite(state, what);
  const auto& w = config.walls;
  const double left = w.left_x + w.radius, right = w.right_x - w.radius, table = table_height(w),
               ceiling = w.ceiling_y - w.radius;
  for (std::size_t b = 0; b <= kDiceCount; ++b) {
    const std::size_t at = b == 0 ? state_index::kCupX : state_index::die(b - 1);
    const std::string body = b == 0 ? "the cup" : "die " + std::to_string(b - 1);
    const double x = state[at], y = state[at + 1];
    char text[200];
    if (x <= left || x >= right)
      std::snprintf(text, sizeof text, ": %s is beyond the walls (x = %g m; the inside is %.2f to %.2f m)", body.c_str(), x,
                    left, right);
    else if (y <= table)
      std::snprintf(text, sizeof text, ": %s is under the table (y = %g m; its surface is at %.2f m)", body.c_str(), y, table);
    else if (y >= ceiling)
      std::snprintf(text, sizeof text, ": %s is above the ceiling (y = %g m; it is at %.2f m)", body.c_str(), y, ceiling);
    else
      continue;
    throw InputError(std::string(what) + text);
  }
  World probe(config);
  probe.set_state(state);
  const std::string overlap = probe.first_overlap();
  if (!overlap.empty()) throw InputError(std::string(what) + ": " + overlap + " (a body inside another)");
}

}  // namespace dicestack
