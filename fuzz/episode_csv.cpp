// Episode CSV text -> parse_episode_csv (what read_demo_set runs on every episode file). An
// accepted episode, given the final state meta.json gives a file with rewards, must pass
// check_episode (equal lengths, finite values, one kind of action, the arm's readings).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <dicestack/datasets/demo_set.hpp>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dicestack;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Episode episode;
  if (!fuzz::accepted([&] { episode = parse_episode_csv(text, "fuzz/episode.csv", "episode"); }, "fuzz/episode.csv:")) return 0;
  // A file with rewards comes with a final state from meta.json (read_demo_set refuses one without).
  if (!episode.rewards.empty()) episode.final_state = episode.states.back();
  if (!fuzz::accepted([&] { check_episode(episode); }, "episode")) fuzz::finding("an accepted episode fails check_episode");
  return 0;
}
