#include "snake/reference_image.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "mesh/byte_codec.h"
#include "mesh/errors.h"
#include "wavelets/model_io.h"

namespace mrsnake {

namespace {
constexpr char kMagic[8] = {'M', 'R', 'S', 'N', 'K', 'R', 'E', 'F'};
constexpr std::uint32_t kVersion = 1;
constexpr std::size_t kHeaderBytes = 8 + 4 + 3 * 4 + 15 * 8;  // magic, version, size, spacing, origin, direction
constexpr std::uint32_t kMaxAxis = 1024;

InputError defect(const std::string& what) {
  return InputError("the model's reference image section " + what + "; rebuild the model with build-model --image");
}

}  // namespace

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

std::vector<std::uint8_t> serialize_reference_image(const Volume& r) {
  ByteWriter b(std::vector<std::uint8_t>(kMagic, kMagic + 8));
  b.put<std::uint32_t>(kVersion);
  for (int a = 0; a < 3; ++a) b.put<std::uint32_t>(static_cast<std::uint32_t>(r.size[a]));
  for (double s : r.spacing) b.put<double>(s);
  for (double o : r.origin) b.put<double>(o);
  for (double d : r.direction) b.put<double>(d);
  for (float v : r.data) b.put<float>(v);
  b.put<std::uint64_t>(fnv1a64(b.bytes().data(), b.bytes().size()));
  return b.take();
}

Volume deserialize_reference_image(const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    throw defect("is not in a format this build reads");
  ByteReader r(bytes, 8, defect("is truncated").what());
  if (r.get<std::uint32_t>() != kVersion) throw defect("has a version this build does not read");
  Volume v;
  for (int a = 0; a < 3; ++a) {
    const std::uint32_t n = r.get<std::uint32_t>();
    if (n < 8 || n > kMaxAxis) throw defect("has an impossible size");
    v.size[a] = n;
  }
  for (double& s : v.spacing) s = r.get<double>();
  for (double& o : v.origin) o = r.get<double>();
  for (double& d : v.direction) d = r.get<double>();
  const std::size_t expected = kHeaderBytes + 4 * v.num_voxels() + 8;
  if (bytes.size() < expected) throw defect("is truncated");
  if (bytes.size() > expected) throw defect("has trailing bytes");
  // The header reader stands at the voxels (kHeaderBytes); the checksum follows them.
  v.data.resize(v.num_voxels());
  for (float& x : v.data) x = r.get<float>();
  if (r.get<std::uint64_t>() != fnv1a64(bytes.data(), expected - 8))
    throw defect("was altered or corrupted (its checksum does not match)");
  for (int a = 0; a < 3; ++a)
    // Bounds far beyond any scanner's (µm to m voxels, km away) keep index arithmetic finite.
    if (!(v.spacing[a] >= 1e-3 && v.spacing[a] <= 1e3) || !(std::abs(v.origin[a]) <= 1e7))
      throw defect("has an impossible frame");
  // The direction must be a rotation or a reflection: orthonormal columns.
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      double dot = 0;
      for (int c = 0; c < 3; ++c) dot += v.direction[3 * c + a] * v.direction[3 * c + b];
      if (!(std::abs(dot - (a == b ? 1.0 : 0.0)) < 1e-6))
        throw defect("has a direction matrix that is not orthonormal");
    }
  for (float x : v.data)
    if (!std::isfinite(x)) throw defect("holds non-finite values");
  return v;
}

void reference_image_to_json(nlohmann::json& j, const Volume& r) {
  std::array<double, 3> extent{};
  for (int a = 0; a < 3; ++a) extent[a] = static_cast<double>(r.size[a]) * r.spacing[a];
  j = nlohmann::json{{"size", r.size},           {"spacing", r.spacing}, {"origin", r.origin},
                     {"direction", r.direction}, {"extent_mm", extent},  {"voxels", r.num_voxels()}};
}

}  // namespace mrsnake
