// One regressor's payload loader, then a prediction: RegressorRegistry::create(DICESTACK_FUZZ_
// REGRESSOR) -> load_payload(bytes, input_dim, output_dim) -> predict_row on a fixed finite
// row. The model file's checksums are bypassed on purpose: they keep out accidents, not an
// adversary, so the loader itself must refuse whatever it cannot use. Built once per built-in
// regressor (fuzz_payload_knn, ...). Input layout: payload_input.hpp. An accepted payload must
// also save and load again into a fresh regressor that predicts the same row bit for bit.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include <dicestack/regressors/registry.hpp>

#include "fuzz_common.hpp"
#include "payload_input.hpp"

#ifndef DICESTACK_FUZZ_REGRESSOR
#error "DICESTACK_FUZZ_REGRESSOR names the regressor this harness loads"
#endif

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace dicestack;
  constexpr const char* kName = DICESTACK_FUZZ_REGRESSOR;
  fuzz::PayloadInput in;
  if (!fuzz::split_payload_input(data, size, in)) return 0;
  const auto& registry = RegressorRegistry::global();
  const auto settings = fuzz::load_settings(kName);
  auto regressor = registry.create(kName, settings);
  const std::vector<double> row = fuzz::fixed_row(in.input_dim);
  std::vector<double> y(in.output_dim), again(in.output_dim);
  const std::string who = std::string(kName) + ":";
  if (!fuzz::accepted([&] { regressor->load_payload(in.payload, in.input_dim, in.output_dim); }, who)) return 0;
  if (!fuzz::accepted([&] { regressor->predict_row(row, y); }, who)) fuzz::finding("a loaded model refuses a valid row");
  std::string saved;
  if (!fuzz::accepted([&] { saved = regressor->save_payload(); }, who)) fuzz::finding("a loaded model cannot be saved");
  auto fresh = registry.create(kName, settings);
  if (!fuzz::accepted([&] { fresh->load_payload(saved, in.input_dim, in.output_dim); }, who))
    fuzz::finding("a loaded model's saved payload is refused");
  fresh->predict_row(row, again);
  if (std::memcmp(y.data(), again.data(), y.size() * sizeof(double)) != 0)
    fuzz::finding("a loaded model predicts differently after save and load");
  return 0;
}
