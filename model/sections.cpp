#include "model/sections.h"

#include <cmath>
#include <cstring>
#include <string>

#include "mesh/errors.h"
#include "model/byte_codec.h"
#include "model/model_io.h"

namespace mrsnake {

namespace {
// The appearance section.
constexpr char kAppearanceMagic[8] = {'M', 'R', 'S', 'A', 'P', 'P', '0', '2'};
// Version 01 differs only in having no centre byte per level.
constexpr char kAppearanceMagicVersion01[8] = {'M', 'R', 'S', 'A', 'P', 'P', '0', '1'};

constexpr const char* kAppearanceTruncated = "the model's appearance section is truncated";
}  // namespace

std::vector<std::uint8_t> serialize_appearance(const Appearance& a) {
  ByteWriter b(std::vector<std::uint8_t>(kAppearanceMagic, kAppearanceMagic + 8));
  b.put<std::int32_t>(a.half_length);
  b.put<std::int32_t>(static_cast<std::int32_t>(a.levels.size()));
  b.put<double>(a.region.inside);
  b.put<double>(a.region.outside);
  b.put<double>(a.inside_spread);
  b.put<double>(a.outside_spread);
  b.put<double>(a.shell_mm);
  for (const LevelAppearance& l : a.levels) {
    b.put<double>(l.spacing_mm);
    b.put<std::uint8_t>(l.centre == ProfileCentre::edges ? 1 : 0);
    b.put<std::int32_t>(static_cast<std::int32_t>(l.profiles.rows()));
    b.put<std::int32_t>(static_cast<std::int32_t>(l.profiles.cols()));
    for (int r = 0; r < l.profiles.rows(); ++r)
      for (int c = 0; c < l.profiles.cols(); ++c) b.put<float>(l.profiles(r, c));
  }
  return b.take();
}

Appearance deserialize_appearance(const std::vector<std::uint8_t>& bytes) {
  const bool version01 = bytes.size() >= 8 && std::memcmp(bytes.data(), kAppearanceMagicVersion01, 8) == 0;
  if (bytes.size() < 8 || (!version01 && std::memcmp(bytes.data(), kAppearanceMagic, 8) != 0))
    throw InputError("the model's appearance section is not in a format this build reads; rebuild the model");
  ByteReader r(bytes, 8, InputError(kAppearanceTruncated, Remedy::rebuild_model_with_image));
  Appearance a;
  a.half_length = r.get<std::int32_t>();
  const int levels = r.get<std::int32_t>();
  if (a.half_length < 0 || a.half_length > 1000 || levels < 0 || levels > 64)
    throw InputError("the model's appearance section is inconsistent; rebuild the model");
  a.region.inside = r.get<double>();
  a.region.outside = r.get<double>();
  a.inside_spread = r.get<double>();
  a.outside_spread = r.get<double>();
  a.shell_mm = r.get<double>();
  // The segmentation divides by the spreads and compares with the medians: a non-finite one
  // would silently derail it, so it is a defect of the model, not a value to use.
  for (double x : {a.region.inside, a.region.outside, a.inside_spread, a.outside_spread, a.shell_mm})
    if (!std::isfinite(x))
      throw InputError("the model's appearance section holds non-finite statistics; rebuild the model");
  for (int j = 0; j < levels; ++j) {
    LevelAppearance l;
    l.spacing_mm = r.get<double>();
    if (version01) {
      l.centre = ProfileCentre::unrecorded;
    } else {
      const auto centred = r.get<std::uint8_t>();
      if (centred > 1) throw InputError("the model's appearance section is inconsistent; rebuild the model");
      l.centre = centred == 1 ? ProfileCentre::edges : ProfileCentre::labels;
    }
    const int rows = r.get<std::int32_t>(), cols = r.get<std::int32_t>();
    if (rows < 0 || cols != 2 * a.half_length + 1 || !(l.spacing_mm > 0) ||
        static_cast<std::size_t>(rows) * cols * sizeof(float) > bytes.size() - r.position())
      throw InputError("the model's appearance section is inconsistent; rebuild the model");
    l.profiles.resize(rows, cols);
    for (int i = 0; i < rows; ++i)
      for (int c = 0; c < cols; ++c) l.profiles(i, c) = r.get<float>();
    if (!l.profiles.allFinite() || !std::isfinite(l.spacing_mm))
      throw InputError("the model's appearance section holds non-finite profiles; rebuild the model");
    a.levels.push_back(std::move(l));
  }
  if (r.position() != bytes.size())
    throw InputError("the model's appearance section has trailing bytes; rebuild the model");
  return a;
}

namespace {
constexpr char kReferenceMagic[8] = {'M', 'R', 'S', 'N', 'K', 'R', 'E', 'F'};
constexpr std::uint32_t kReferenceVersion = 1;
constexpr std::size_t kHeaderBytes = 8 + 4 + 3 * 4 + 15 * 8;  // magic, version, size, spacing, origin, direction
constexpr std::uint32_t kMaxAxis = 1024;

InputError defect(const std::string& what) {
  return InputError("the model's reference image section " + what, Remedy::rebuild_model_with_image);
}

}  // namespace

std::vector<std::uint8_t> serialize_reference_image(const Volume& r) {
  ByteWriter b(std::vector<std::uint8_t>(kReferenceMagic, kReferenceMagic + 8));
  b.put<std::uint32_t>(kReferenceVersion);
  for (int a = 0; a < 3; ++a) b.put<std::uint32_t>(static_cast<std::uint32_t>(r.size[a]));
  for (double s : r.spacing) b.put<double>(s);
  for (double o : r.origin) b.put<double>(o);
  for (double d : r.direction) b.put<double>(d);
  for (float v : r.data) b.put<float>(v);
  b.put<std::uint64_t>(fnv1a64(b.bytes().data(), b.bytes().size()));
  return b.take();
}

Volume deserialize_reference_image(const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kReferenceMagic, 8) != 0)
    throw defect("is not in a format this build reads");
  ByteReader r(bytes, 8, defect("is truncated"));
  if (r.get<std::uint32_t>() != kReferenceVersion) throw defect("has a version this build does not read");
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

}  // namespace mrsnake
