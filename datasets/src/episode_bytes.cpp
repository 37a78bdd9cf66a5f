#include <dicestack/datasets/episode_bytes.hpp>

namespace dicestack {

void pack_episode(Packer& out, const Episode& e) {
  out.put_string(e.name).put(e.seed).put_vector(e.states).put_vector(e.actions).put_vector(e.sources).put_vector(e.links);
  out.put(e.outcome).put_string(e.origin).put<std::uint8_t>(e.final_state.has_value());
  if (e.final_state) out.put(*e.final_state);
  out.put_vector(e.rewards).put<std::uint8_t>(e.terminated).put<std::uint8_t>(e.truncated).put_string(e.perturbation);
  out.put_vector(e.joint_torques).put<std::uint8_t>(e.final_links.has_value());
  if (e.final_links) out.put(*e.final_links);
}

Episode unpack_episode(Unpacker& in) {
  Episode e;
  e.name = in.get_string();
  e.seed = in.get<std::uint64_t>();
  e.states = in.get_vector<State>();
  e.actions = in.get_vector<Action>();
  e.sources = in.get_vector<StepSource>();
  e.links = in.get_vector<ArmLinks>();
  e.outcome = in.get<Outcome>();
  e.origin = in.get_string();
  if (in.get<std::uint8_t>()) e.final_state = in.get<State>();
  e.rewards = in.get_vector<double>();
  e.terminated = in.get<std::uint8_t>() != 0;
  e.truncated = in.get<std::uint8_t>() != 0;
  e.perturbation = in.get_string();
  e.joint_torques = in.get_vector<std::array<double, 4>>();
  if (in.get<std::uint8_t>()) e.final_links = in.get<ArmLinks>();
  return e;
}

std::string episode_to_bytes(const Episode& e) {
  Packer p;
  pack_episode(p, e);
  return p.take();
}

Episode episode_from_bytes(std::string_view bytes) {
  Unpacker u(bytes, "episode");
  return unpack_episode(u);
}

}  // namespace dicestack
