// Tests of the untangling of a level that passes through itself (remesh/untangle.h).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

#include "mesh/distance.h"
#include "mesh/primitives.h"
#include "remesh/untangle.h"

namespace mrsnake {
namespace {

// An icosphere with one vertex pushed through the far side: its faces pierce the sphere.
struct PiercedSphere {
  TriMesh sphere = icosphere(3, 10.0);
  int pushed = 5;
  RowMatrixX3d X;
  PiercedSphere() : X(sphere.V) { X.row(pushed) = -1.3 * sphere.V.row(pushed); }
};

// The corners of the faces of `pairs`.
std::set<int> corners_of(const std::vector<std::pair<int, int>>& pairs, const RowMatrixX3i& F) {
  std::set<int> corners;
  for (const auto& [f, g] : pairs)
    for (int k = 0; k < 3; ++k) corners.insert({F(f, k), F(g, k)});
  return corners;
}

// The mean of v's neighbours, each once (on a closed surface the umbrella of the star).
Eigen::RowVector3d neighbour_mean(const RowMatrixX3d& X, const RowMatrixX3i& F, int v) {
  std::set<int> ring;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == v) ring.insert({F(f, (k + 1) % 3), F(f, (k + 2) % 3)});
  Eigen::RowVector3d sum = Eigen::RowVector3d::Zero();
  for (int u : ring) sum += X.row(u);
  return sum / static_cast<double>(ring.size());
}

TEST(Untangle, OneRoundOpensAPiercingAndMovesOnlyTheCornersOfTheIntersectingFaces) {
  const PiercedSphere p;
  const auto pairs = crossing_face_pairs(TriMesh{p.X, p.sphere.F});
  ASSERT_FALSE(pairs.empty());
  const std::set<int> corners = corners_of(pairs, p.sphere.F);
  ASSERT_TRUE(corners.count(p.pushed));

  RowMatrixX3d X = p.X;
  const UntangleStats stats = untangle_self_intersections(p.sphere.F, X, {});
  EXPECT_EQ(stats.pairs_before, static_cast<int>(pairs.size()));
  EXPECT_EQ(stats.pairs_after, 0);
  EXPECT_EQ(count_self_intersections(TriMesh{X, p.sphere.F}), 0);
  EXPECT_EQ(stats.rounds, 1);
  EXPECT_EQ(stats.moved_vertices, static_cast<int>(corners.size()));
  // All at once, from the positions before the round: each corner at its neighbours' mean
  // there, and every other vertex exactly where it was.
  for (int v = 0; v < X.rows(); ++v) {
    if (corners.count(v))
      EXPECT_LT((X.row(v) - neighbour_mean(p.X, p.sphere.F, v)).norm(), 1e-12) << v;
    else
      EXPECT_EQ(X.row(v), p.X.row(v)) << v;
  }
  // The pushed vertex is back near the sphere, on its own side.
  EXPECT_GT(X.row(p.pushed).dot(p.sphere.V.row(p.pushed)), 0.0);
}

TEST(Untangle, FixedVerticesStayAndTheCountNeverRises) {
  const PiercedSphere p;
  std::vector<bool> fixed(p.X.rows(), false);
  fixed[p.pushed] = true;
  RowMatrixX3d X = p.X;
  const UntangleStats stats = untangle_self_intersections(p.sphere.F, X, fixed);
  EXPECT_EQ(X.row(p.pushed), p.X.row(p.pushed));
  // The pushed vertex's own faces still pierce the sphere: some pairs stay.
  EXPECT_GT(stats.pairs_after, 0);
  EXPECT_LE(stats.pairs_after, stats.pairs_before);
  EXPECT_EQ(stats.pairs_after, static_cast<int>(crossing_face_pairs(TriMesh{X, p.sphere.F}).size()));
}

// Two triangles through each other's centre, each alone: the umbrella step turns each into its
// medial triangle, mirrored through the common centre, so they still cross. The round does
// not lower the count, and is undone.
TEST(Untangle, ARoundThatDoesNotLowerTheCountIsUndone) {
  const double s = std::sqrt(3.0) / 2;
  RowMatrixX3d X(6, 3);
  X << 1, 0, 0, -0.5, s, 0, -0.5, -s, 0,                 // in the plane z = 0
      0, 0, 0.5, 0, 0.5 * s, -0.25, 0, -0.5 * s, -0.25;  // in the plane x = 0
  RowMatrixX3i F(2, 3);
  F << 0, 1, 2, 3, 4, 5;
  ASSERT_EQ(crossing_face_pairs(TriMesh{X, F}).size(), 1u);
  const RowMatrixX3d before = X;
  const UntangleStats stats = untangle_self_intersections(F, X, {});
  EXPECT_EQ(stats.pairs_before, 1);
  EXPECT_EQ(stats.pairs_after, 1);
  EXPECT_EQ(stats.rounds, 0);
  EXPECT_EQ(stats.moved_vertices, 0);
  EXPECT_EQ(X, before);
  // A wrong number of fixed flags is refused.
  EXPECT_THROW(untangle_self_intersections(F, X, std::vector<bool>(5, false)), std::invalid_argument);
}

TEST(Untangle, ACleanSurfaceOrNoRoundsLeaveEveryVertex) {
  const TriMesh sphere = icosphere(3, 10.0);
  RowMatrixX3d X = sphere.V;
  const UntangleStats clean = untangle_self_intersections(sphere.F, X, {});
  EXPECT_EQ(clean.pairs_before, 0);
  EXPECT_EQ(clean.moved_vertices, 0);
  EXPECT_EQ(X, sphere.V);

  const PiercedSphere p;
  RowMatrixX3d off = p.X;
  UntangleOptions none;
  none.max_rounds = 0;
  const UntangleStats stats = untangle_self_intersections(p.sphere.F, off, {}, none);
  EXPECT_EQ(stats.rounds, 0);
  EXPECT_EQ(off, p.X);
}

}  // namespace
}  // namespace mrsnake
