// Episode CSV text -> parse_episode_csv (what read_demo_set runs on every episode file). An
// accepted episode must pass check_episode (equal lengths, finite values).
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <dicestack/datasets/demo_set.hpp>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dicestack;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Episode episode;
  if (fuzz::accepted([&] { episode = parse_episode_csv(text, "fuzz/episode.csv", "episode"); }, "fuzz/episode.csv:"))
    if (!fuzz::accepted([&] { check_episode(episode); }, "episode")) fuzz::finding("an accepted episode fails check_episode");
  return 0;
}
