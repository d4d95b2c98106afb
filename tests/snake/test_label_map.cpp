// One label map from overlapping structures (snake/label_map.h).
#include <gtest/gtest.h>

#include <cmath>

#include "snake/label_map.h"
#include "tests/wavelets/hierarchies.h"

using namespace mrsnake;

namespace {

// A sphere of `radius` mm around `centre`: the bumpy sphere's vertices pushed onto it.
TriMesh sphere(const Eigen::Vector3d& centre, double radius) {
  const test::Hierarchy h = test::bumpy_sphere(4);
  TriMesh m{h.finest, h.conn.faces.back()};
  const Eigen::Vector3d middle = m.V.colwise().mean().transpose();
  for (Eigen::Index v = 0; v < m.V.rows(); ++v)
    m.V.row(v) = (centre + radius * (m.V.row(v).transpose() - middle).normalized()).transpose();
  return m;
}

}  // namespace

TEST(StructureLabelMap, TwoOverlappingSpheresSplitTheirOverlapAtTheMiddle) {
  Volume grid;
  grid.size = {40, 40, 40};
  grid.data.assign(grid.num_voxels(), 0.0f);
  const Eigen::Vector3d a(15, 20, 20), b(25, 20, 20);
  const double r = 8.0;
  const StructureLabelMap map = structure_label_map({sphere(a, r), sphere(b, r)}, {3, 7}, grid);
  // 0.3 mm away from either sphere, the tessellation cannot change a voxel's side.
  long inside_both = 0, union_voxels = 0, checked = 0;
  for (std::size_t k = 0; k < 40; ++k)
    for (std::size_t j = 0; j < 40; ++j)
      for (std::size_t i = 0; i < 40; ++i) {
        const Eigen::Vector3d p(i, j, k);
        const double da = (p - a).norm(), db = (p - b).norm();
        if (std::abs(da - r) < 0.3 || std::abs(db - r) < 0.3) continue;
        const float label = map.labels.at(i, j, k);
        const bool in_a = da < r, in_b = db < r;
        union_voxels += in_a || in_b;
        inside_both += in_a && in_b;
        float expected = 0;
        if (in_a && in_b) {
          if (i == 20) continue;            // the tie plane: either is right
          expected = i < 20 ? 3.0f : 7.0f;  // deeper inside the sphere whose centre is nearer
        } else if (in_a || in_b) {
          expected = in_a ? 3.0f : 7.0f;
        }
        ++checked;
        ASSERT_EQ(label, expected) << "voxel " << i << " " << j << " " << k;
      }
  EXPECT_GT(inside_both, 100);
  EXPECT_GT(checked, 60000);
  // Every contested voxel counts for both claimants; each voxel is held by one structure only.
  EXPECT_EQ(map.contested[0], map.contested[1]);
  EXPECT_GE(map.contested[0], inside_both);
  long labelled = 0;
  for (const float v : map.labels.data) labelled += v != 0.0f;
  EXPECT_EQ(labelled, map.voxels[0] + map.voxels[1]);
  EXPECT_NEAR(static_cast<double>(map.voxels[0]), static_cast<double>(map.voxels[1]), 0.02 * map.voxels[0]);
  EXPECT_GE(labelled, union_voxels);
}
