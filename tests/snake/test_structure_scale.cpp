// The structure's size and the build-model defaults derived from it (snake/structure_scale.h).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "mesh/marching_cubes.h"
#include "snake/structure_scale.h"

using namespace mrsnake;

namespace {

// A ball of `radius` voxels of label 2 in an n³ grid of voxels `spacing` (x, y) and
// `spacing_z` (z) mm.
Volume ball(std::size_t n, double radius, double spacing, double spacing_z) {
  Volume v;
  v.size = {n, n, n};
  v.spacing = {spacing, spacing, spacing_z};
  v.data.assign(v.num_voxels(), 0.0f);
  const double c = 0.5 * (static_cast<double>(n) - 1.0);
  for (std::size_t k = 0; k < n; ++k)
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t i = 0; i < n; ++i) {
        const double x = i - c, y = j - c, z = k - c;
        if (x * x + y * y + z * z <= radius * radius) v.at(i, j, k) = 2.0f;
      }
  return v;
}

}  // namespace

TEST(StructureScale, MeasuresVolumeRadiusAndExtentInMillimetres) {
  const Volume v = ball(40, 12.0, 0.25, 0.25);
  const StructureScale s = measure_structure(v, 2);
  double voxels = 0;
  for (float x : v.data) voxels += x == 2.0f;
  EXPECT_DOUBLE_EQ(s.volume_mm3, voxels * 0.25 * 0.25 * 0.25);
  EXPECT_NEAR(s.equivalent_radius_mm, 12.0 * 0.25, 0.02);  // a voxelized ball of radius 12 voxels
  EXPECT_EQ(s.finest_voxel_mm, 0.25);
  EXPECT_EQ(s.largest_voxel_mm, 0.25);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(s.extent_mm[a], 24 * 0.25, 1e-6);  // centres 23 voxels apart, plus one
  // No voxel of the label: zeros, so that the surface extraction says which labels there are.
  const StructureScale none = measure_structure(v, 7);
  EXPECT_EQ(none.volume_mm3, 0.0);
  EXPECT_EQ(default_marching_cubes_spacing(none), 0.0);
}

TEST(StructureScale, MarchingCubesSpacingFollowsTheStructureAndItsVoxels) {
  StructureScale s;
  s.equivalent_radius_mm = 72.0;  // a liver
  s.finest_voxel_mm = 0.6;
  s.largest_voxel_mm = 1.3;
  EXPECT_DOUBLE_EQ(default_marching_cubes_spacing(s), 72.0 / kCellsPerRadius);  // resampled to 1.2 mm
  s.equivalent_radius_mm = 1.65;  // a mouse hippocampus at 0.15 mm: its own voxels
  s.finest_voxel_mm = s.largest_voxel_mm = 0.15;
  EXPECT_EQ(default_marching_cubes_spacing(s), 0.0);
  s.largest_voxel_mm = 1.0;  // thick slices: resampled to the finest side, no slice staircase
  EXPECT_DOUBLE_EQ(default_marching_cubes_spacing(s), 0.15);
  // Every length scales with the structure.
  StructureScale tenth = s;
  tenth.equivalent_radius_mm /= 10;
  tenth.finest_voxel_mm /= 10;
  tenth.largest_voxel_mm /= 10;
  EXPECT_NEAR(default_marching_cubes_spacing(tenth), 0.1 * default_marching_cubes_spacing(s), 1e-12);
  EXPECT_NEAR(default_reference_margin(tenth), 0.1 * default_reference_margin(s), 1e-12);
  EXPECT_DOUBLE_EQ(default_reference_margin(s), kReferenceMarginRadii * 1.65);
}

TEST(StructureScale, FaceCountCoversTheAreaWithHalfVoxelEdgesWithinItsBounds) {
  const Volume v = ball(40, 12.0, 1.0, 1.0);
  const TriMesh surface = extract_label_surface(v, 2, {}).mesh;
  double area = 0;
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f) {
    const Eigen::Vector3d a = surface.V.row(surface.F(f, 0)), b = surface.V.row(surface.F(f, 1)),
                          c = surface.V.row(surface.F(f, 2));
    area += 0.5 * (b - a).cross(c - a).norm();
  }
  const double expected = area / (std::sqrt(3.0) / 4.0 * 0.5 * 0.5);  // edges of 0.5 for a sampling of 1
  EXPECT_NEAR(default_face_count(surface, 1.0, 16, 1 << 30), expected, 1.0);
  EXPECT_EQ(default_face_count(surface, 1.0, 1024, 2048), 2048);     // clamped above
  EXPECT_EQ(default_face_count(surface, 100.0, 1024, 32768), 1024);  // and below
  // Degenerate sampling lengths give the cap, never an overflow.
  EXPECT_EQ(default_face_count(surface, 1e-300, 1024, 32768), 32768);
  EXPECT_EQ(default_face_count(surface, 0.0, 1024, 32768), 32768);
}
