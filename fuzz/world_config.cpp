// World config JSON text -> world_config_from_json. An accepted config must pass validate()
// and survive to_json -> world_config_from_json unchanged.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <dicestack/core/world_config.hpp>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dicestack;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  WorldConfig config;
  if (!fuzz::accepted([&] { config = world_config_from_json(text, "fuzz/world.json"); }, "fuzz/world.json")) return 0;
  if (!fuzz::accepted([&] { validate(config); }, "")) fuzz::finding("an accepted world config fails validate()");
  const std::string json = to_json(config);
  WorldConfig again;
  if (!fuzz::accepted([&] { again = world_config_from_json(json, "fuzz/again.json"); }, "fuzz/again.json"))
    fuzz::finding("an accepted world config does not read back from to_json");
  if (to_json(again) != json) fuzz::finding("an accepted world config changes through to_json");
  return 0;
}
