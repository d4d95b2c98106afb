#include "snake/reference_image.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"

namespace mrsnake {

Volume make_reference_crop(const Volume& image, const RowMatrixX3d& V, const ReferenceImageOptions& options) {
  if (V.rows() == 0) throw InputError("no surface to crop the reference image around");
  if (image.data.size() != image.num_voxels()) throw Error("internal: image buffer does not match its size");
  std::array<double, 3> mn{}, mx{};
  mn.fill(std::numeric_limits<double>::max());
  mx.fill(std::numeric_limits<double>::lowest());
  for (int v = 0; v < V.rows(); ++v) {
    const auto idx = image.physical_to_index({V(v, 0), V(v, 1), V(v, 2)});
    for (int a = 0; a < 3; ++a) {
      mn[a] = std::min(mn[a], idx[a]);
      mx[a] = std::max(mx[a], idx[a]);
    }
  }
  std::array<long, 3> lo{}, hi{}, factor{};
  Volume out;
  for (int a = 0; a < 3; ++a) {
    const double grow = options.margin_mm / image.spacing[a];
    const long last = static_cast<long>(image.size[a]) - 1;
    const double l = std::floor(mn[a] - grow), h = std::ceil(mx[a] + grow);
    if (h < 0 || l > last)
      throw InputError("the model's surface lies outside the reference image; check that they match");
    lo[a] = std::clamp(static_cast<long>(l), 0L, last);
    hi[a] = std::clamp(static_cast<long>(h), 0L, last);
    const long n = hi[a] - lo[a] + 1;
    factor[a] = std::max(1L, (n + options.max_voxels_per_axis - 1) / std::max(1, options.max_voxels_per_axis));
    out.size[a] = static_cast<std::size_t>(n / factor[a]);
    if (out.size[a] < 8)
      throw InputError(
          "the reference image around the model has fewer than 8 voxels along an axis; use a larger image");
    out.spacing[a] = image.spacing[a] * static_cast<double>(factor[a]);
  }
  out.direction = image.direction;
  // The first block's centre: lo + (f − 1)/2 in the image's indices.
  out.origin = image.index_to_physical(lo[0] + 0.5 * (factor[0] - 1), lo[1] + 0.5 * (factor[1] - 1),
                                       lo[2] + 0.5 * (factor[2] - 1));
  out.data.assign(out.num_voxels(), 0.0f);
  const double weight = 1.0 / static_cast<double>(factor[0] * factor[1] * factor[2]);
  for (std::size_t k = 0; k < out.size[2]; ++k)
    for (std::size_t j = 0; j < out.size[1]; ++j)
      for (std::size_t i = 0; i < out.size[0]; ++i) {
        double sum = 0;
        for (long c = 0; c < factor[2]; ++c)
          for (long b = 0; b < factor[1]; ++b)
            for (long a = 0; a < factor[0]; ++a) {
              const float v = image.at(static_cast<std::size_t>(lo[0] + static_cast<long>(i) * factor[0] + a),
                                       static_cast<std::size_t>(lo[1] + static_cast<long>(j) * factor[1] + b),
                                       static_cast<std::size_t>(lo[2] + static_cast<long>(k) * factor[2] + c));
              sum += std::isfinite(v) ? v : 0.0f;
            }
        out.at(i, j, k) = static_cast<float>(sum * weight);
      }
  return out;
}

void reference_image_to_json(nlohmann::json& j, const Volume& r) {
  std::array<double, 3> extent{};
  for (int a = 0; a < 3; ++a) extent[a] = static_cast<double>(r.size[a]) * r.spacing[a];
  j = nlohmann::json{{"size", r.size},           {"spacing", r.spacing}, {"origin", r.origin},
                     {"direction", r.direction}, {"extent_mm", extent},  {"voxels", r.num_voxels()}};
}

}  // namespace mrsnake
