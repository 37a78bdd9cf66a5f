// A demonstration set's meta.json text -> parse_demo_meta (format, version, world config,
// episode entries), as read_demo_set runs it before opening any episode file.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include <dicestack/datasets/demo_set.hpp>

#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dicestack;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  fuzz::accepted([&] { parse_demo_meta(text, "fuzz/meta.json"); }, "fuzz/meta.json");
  return 0;
}
