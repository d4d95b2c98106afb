// libFuzzer harness: the readers of the model's optional sections, which segment trusts once
// the manifest's checksum matched.
//   first byte even: the "reference_image" section (deserialize_reference_image); the harness
//                    rewrites the trailing FNV-1a so that the fuzzer reaches the size, frame
//                    and value checks behind the checksum;
//   first byte odd:  the "appearance" section (deserialize_appearance).
// Any mrsnake::Error is a correct rejection; a crash, or an accepted section holding
// non-finite or impossible values, is a bug.
#include <cmath>
#include <cstdint>
#include <vector>

#include "mesh/errors.h"
#include "snake/appearance.h"
#include "snake/reference_image.h"
#include "model/model_io.h"
#include "model/sections.h"

using namespace mrsnake;

namespace {

void check_reference_image(std::vector<std::uint8_t> bytes) {
  if (bytes.size() >= 16) {
    const std::uint64_t h = fnv1a64(bytes.data(), bytes.size() - 8);
    for (int b = 0; b < 8; ++b) bytes[bytes.size() - 8 + b] = static_cast<std::uint8_t>(h >> (8 * b));
  }
  try {
    const Volume v = deserialize_reference_image(bytes);
    if (v.data.size() != v.num_voxels()) __builtin_trap();
    for (int a = 0; a < 3; ++a)
      if (!(v.spacing[a] > 0) || !std::isfinite(v.spacing[a])) __builtin_trap();
    for (float x : v.data)
      if (!std::isfinite(x)) __builtin_trap();
  } catch (const mrsnake::Error&) {
  }
}

void check_appearance(const std::vector<std::uint8_t>& bytes) {
  try {
    const Appearance a = deserialize_appearance(bytes);
    const int samples = 2 * a.half_length + 1;
    for (const LevelAppearance& l : a.levels) {
      if (l.profiles.cols() != samples || !(l.spacing_mm > 0)) __builtin_trap();
      if (!l.profiles.allFinite()) __builtin_trap();
    }
    for (double x : {a.region.inside, a.region.outside, a.inside_spread, a.outside_spread, a.shell_mm})
      if (!std::isfinite(x)) __builtin_trap();
  } catch (const mrsnake::Error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  std::vector<std::uint8_t> body(data + 1, data + size);
  if (data[0] % 2 == 0)
    check_reference_image(std::move(body));
  else
    check_appearance(body);
  return 0;
}
