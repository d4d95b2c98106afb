// Tests of SplitSweep: the two halves' inner vertices never meet, so a sweep that reads only
// 1-rings gives the same result side by side as one half after the other.
#include <gtest/gtest.h>

#include <mutex>
#include <vector>

#include "mesh/primitives.h"
#include "mesh/vertex_stars.h"
#include "remesh/split_sweep.h"
#include "tests/remesh/remesh_shapes.h"

namespace mrsnake {
namespace {

// The 1-ring neighbours of v.
std::vector<int> ring(const RowMatrixX3i& F, const VertexStars& stars, int v) {
  std::vector<int> out;
  for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i)
    for (int k = 0; k < 3; ++k)
      if (F(stars.faces[i], k) != v) out.push_back(F(stars.faces[i], k));
  return out;
}

// Gauss-Seidel Laplacian smoothing in the order SplitSweep gives, each vertex to the mean of
// its ring.
RowMatrixX3d smoothed(const TriMesh& mesh, int min_parallel) {
  const VertexStars stars(mesh.F, mesh.num_vertices());
  const SplitSweep split(mesh.V, mesh.F, stars, min_parallel);
  RowMatrixX3d X = mesh.V;
  for (int it = 0; it < 3; ++it)
    split.run([&](int part) {
      for (int v = 0; v < X.rows(); ++v) {
        if (split.part(v) != part) continue;
        Eigen::RowVector3d mean = Eigen::RowVector3d::Zero();
        const std::vector<int> around = ring(mesh.F, stars, v);
        for (int w : around) mean += X.row(w) / static_cast<double>(around.size());
        X.row(v) = mean;
      }
    });
  return X;
}

TEST(SplitSweep, InnerVerticesKeepTheirRingInTheirHalf) {
  for (const TriMesh& mesh : {test::ellipsoid(4), test::spherical_cap(4), icosphere(3)}) {
    const VertexStars stars(mesh.F, mesh.num_vertices());
    const SplitSweep split(mesh.V, mesh.F, stars);
    std::vector<int> count(SplitSweep::kParts, 0);
    for (int v = 0; v < mesh.num_vertices(); ++v) {
      ++count[split.part(v)];
      // An inner vertex's neighbours are of its half (inner or band): no face or edge joins
      // the two halves' inner vertices.
      if (split.part(v) == SplitSweep::kBand) continue;
      for (int w : ring(mesh.F, stars, v))
        EXPECT_TRUE(split.part(w) == split.part(v) || split.part(w) == SplitSweep::kBand);
    }
    // Halves of about half the vertices each, and a band along one cut only.
    EXPECT_GT(count[0], mesh.num_vertices() * 35 / 100);
    EXPECT_GT(count[1], mesh.num_vertices() * 35 / 100);
    EXPECT_LT(count[SplitSweep::kBand], mesh.num_vertices() * 20 / 100);
  }
}

TEST(SplitSweep, BothHalvesEndBeforeTheBandBegins) {
  const TriMesh mesh = icosphere(4);
  const VertexStars stars(mesh.F, mesh.num_vertices());
  const SplitSweep split(mesh.V, mesh.F, stars, 0);
  std::mutex lock;
  std::vector<int> ended;
  split.run([&](int part) {
    const std::lock_guard<std::mutex> hold(lock);
    ended.push_back(part);
  });
  ASSERT_EQ(ended.size(), 3u);
  EXPECT_EQ(ended.back(), SplitSweep::kBand);
}

TEST(SplitSweep, SideBySideGivesTheSameResultAsOneAfterTheOther) {
  const TriMesh mesh = test::ellipsoid(5);  // 10242 vertices
  const RowMatrixX3d sequential = smoothed(mesh, 1 << 30);
  const RowMatrixX3d side_by_side = smoothed(mesh, 0);
  EXPECT_TRUE(sequential == side_by_side) << (sequential - side_by_side).cwiseAbs().maxCoeff();
  EXPECT_GT((sequential - mesh.V).cwiseAbs().maxCoeff(), 0.0);  // the sweep did move vertices
}

}  // namespace
}  // namespace mrsnake
