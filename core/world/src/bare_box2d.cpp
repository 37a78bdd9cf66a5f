#include <dicestack/core/bare_box2d.hpp>

#include <chrono>

#include "scene.hpp"
#include <dicestack/core/initial_state.hpp>
#include <dicestack/core/rng.hpp>

namespace dicestack {

using detail::make_world_storage;
using detail::poses_of;
using detail::Scene;
using detail::WorldStorage;

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
