#pragma once
// World's private state, shared by world.cpp and snapshot.cpp. Private to core/world.
#include <array>
#include <optional>

#include <dicestack/core/world.hpp>

#include "scene.hpp"

namespace dicestack {

struct World::Impl {
  WorldConfig config;
  float sub_dt;
  float wall_contact_gap;  // Box2D units
  detail::WorldStorage storage = detail::make_world_storage();
  std::optional<detail::Scene> scene;  // lives in `storage`

  // Replaces the scene; the old one is destroyed first so that both use the same storage.
  detail::Scene& rebuild(const std::array<detail::Pose, detail::kBodies>& poses, const ArmLinks* links = nullptr) {
    scene.reset();
    return scene.emplace(config, poses, storage.get(), links);
  }

  explicit Impl(const WorldConfig& c) : config(c) {
    validate(config);
    sub_dt = static_cast<float>(config.physics.control_dt / config.physics.substeps);
    wall_contact_gap = static_cast<float>(config.judge.wall_contact_distance * config.physics.units_per_metre);
  }

  bool touches_wall() const {
    for (b2Contact* c = scene->world->GetContactList(); c; c = c->GetNext()) {
      if (!c->IsTouching()) continue;
      const int a = detail::fixture_id(c->GetFixtureA()), b = detail::fixture_id(c->GetFixtureB());
      if (!detail::is_side_wall_or_ceiling(a) && !detail::is_side_wall_or_ceiling(b)) continue;
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
    put(state_index::kCupX, scene->bodies[0]);
    put_velocity(state_index::kCupVx, scene->bodies[0]);
    for (std::size_t i = 0; i < kDiceCount; ++i) {
      put(state_index::die(i), scene->bodies[i + 1]);
      put_velocity(state_index::die(i) + 3, scene->bodies[i + 1]);
    }
    return s;
  }
};

}  // namespace dicestack
