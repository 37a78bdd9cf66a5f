#pragma once
// PNG bytes of an image, written with zlib alone: a rendered frame needs no image codec
// library (OpenCV's pulls in over a hundred shared libraries at every program start).
#include <cstdint>
#include <vector>

#include <dicestack/core/render.hpp>

namespace dicestack {

/// `image` (BGR, 8 bits) as a PNG file's bytes: RGB, 8 bits per channel, one IDAT chunk.
/// Deterministic: the same image, the same bytes. Throws InputError for an inconsistent image.
std::vector<std::uint8_t> encode_png(const Image& image);

}  // namespace dicestack
