// A whole model file (JSON header line + payload) -> parse_model_file, then Model::act on a
// fixed history. Before parsing, the harness reseals the file: if the header is a JSON object
// whose "payload_fnv1a" and "checksum" are strings, they are replaced by the right values
// (docs/formats.md: FNV-1a over the payload; over the header without "checksum", as dumped, a
// newline and the payload). The checksums keep out accidents, not an adversary; resealing lets
// the fuzzer reach every header field, the parameters and the payload loaders behind them.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include <dicestack/core/hash.hpp>
#include <dicestack/core/json_depth.hpp>
#include <dicestack/core/types.hpp>
#include <dicestack/regressors/model.hpp>

#include "fuzz_common.hpp"

namespace {

std::string hex(std::uint64_t h) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(h));
  return text;
}

std::string resealed(std::string_view file) {
  using nlohmann::json;
  const auto newline = file.find('\n');
  if (newline == std::string_view::npos) return std::string(file);
  const std::string_view payload = file.substr(newline + 1);
  json h;
  try {
    h = dicestack::parse_json_limited<json>(file.substr(0, newline), "fuzz");
  } catch (const std::exception&) {
    return std::string(file);
  }
  if (!h.is_object() || !h.contains("payload_fnv1a") || !h["payload_fnv1a"].is_string()) return std::string(file);
  h["payload_fnv1a"] = hex(dicestack::fnv1a(payload));
  if (h.contains("checksum") && h["checksum"].is_string()) {
    h.erase("checksum");
    h["checksum"] = hex(dicestack::fnv1a(h.dump() + '\n' + std::string(payload)));
  }
  return h.dump() + '\n' + std::string(payload);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dicestack;
  const std::string file = resealed({reinterpret_cast<const char*>(data), size});
  const auto& registry = RegressorRegistry::global();
  std::unique_ptr<Model> model;
  if (!fuzz::accepted([&] { model = std::make_unique<Model>(parse_model_file(file, "fuzz/model.dsm", registry)); },
                      "fuzz/model.dsm"))
    return 0;
  const State state{};
  if (!fuzz::accepted([&] { model->act(state); }, "")) fuzz::finding("a loaded model refuses to act");
  return 0;
}
