#include "snake/structure_scale.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

namespace mrsnake {

StructureScale measure_structure(const Volume& labels, int label) {
  StructureScale s;
  s.finest_voxel_mm = std::min({labels.spacing[0], labels.spacing[1], labels.spacing[2]});
  s.largest_voxel_mm = labels.max_spacing();
  std::array<double, 3> lo{}, hi{};
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  std::size_t count = 0;
  const auto value = static_cast<float>(label);
  for (std::size_t k = 0; k < labels.size[2]; ++k)
    for (std::size_t j = 0; j < labels.size[1]; ++j)
      for (std::size_t i = 0; i < labels.size[0]; ++i) {
        if (labels.data[labels.index(i, j, k)] != value) continue;
        ++count;
        const auto p = labels.index_to_physical(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], p[a]);
          hi[a] = std::max(hi[a], p[a]);
        }
      }
  if (count == 0) return s;  // the caller's surface extraction says which labels there are
  s.volume_mm3 = static_cast<double>(count) * labels.spacing[0] * labels.spacing[1] * labels.spacing[2];
  s.equivalent_radius_mm = std::cbrt(3.0 * s.volume_mm3 / (4.0 * M_PI));
  // The voxel centres' box, grown by the largest voxel side: a single voxel has a voxel's extent.
  for (int a = 0; a < 3; ++a) s.extent_mm[a] = hi[a] - lo[a] + s.largest_voxel_mm;
  return s;
}

double default_marching_cubes_spacing(const StructureScale& scale) {
  const double wanted = scale.equivalent_radius_mm / kCellsPerRadius;
  if (scale.finest_voxel_mm < wanted) return wanted;
  if (scale.largest_voxel_mm > 1.5 * scale.finest_voxel_mm) return scale.finest_voxel_mm;
  return 0.0;
}

int default_face_count(const TriMesh& surface, double sampling_mm, int min_faces, int max_faces) {
  double area = 0;
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)), b = surface.V.row(surface.F(f, 1)),
                          c = surface.V.row(surface.F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const double edge = 0.5 * sampling_mm;
  const double triangle_area = std::sqrt(3.0) / 4.0 * edge * edge;
  const double faces = area / triangle_area;
  if (!std::isfinite(faces)) return max_faces;
  // Clamped before the rounding: a huge count does not overflow the integer.
  return static_cast<int>(
      std::lround(std::clamp(faces, static_cast<double>(min_faces), static_cast<double>(max_faces))));
}

double default_reference_margin(const StructureScale& scale) {
  return kReferenceMarginRadii * scale.equivalent_radius_mm;
}

void to_json(nlohmann::json& j, const StructureScale& s) {
  j = {{"finest_voxel_mm", s.finest_voxel_mm},
       {"largest_voxel_mm", s.largest_voxel_mm},
       {"volume_mm3", s.volume_mm3},
       {"equivalent_radius_mm", s.equivalent_radius_mm},
       {"extent_mm", s.extent_mm}};
}

}  // namespace mrsnake
