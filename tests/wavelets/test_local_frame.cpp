#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>

#include "tests/wavelets/hierarchies.h"
#include "wavelets/lifting.h"
#include "wavelets/local_frame.h"

using namespace mrsnake;
using namespace mrsnake::test;

namespace {

void expect_orthonormal_right_handed(const LocalFrame& f) {
  EXPECT_LT((f.axes.transpose() * f.axes - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(f.axes.determinant(), 1.0, 1e-14);
}

}  // namespace

TEST(LocalFrame, TangentAlongTheEdgeNormalFromTheFacesScaleTheEdgeLength) {
  const Eigen::Vector3d a(1, 2, 3), b(4, 2, 3);
  const LocalFrame f = parent_edge_frame(a, b, Eigen::Vector3d(0.5, 0.0, 2.0), 1.0, 1e-10);
  EXPECT_FALSE(f.degenerate);
  EXPECT_DOUBLE_EQ(f.scale, 3.0);
  EXPECT_LT((f.axes.col(0) - Eigen::Vector3d::UnitX()).norm(), 1e-15);
  EXPECT_LT((f.axes.col(2) - Eigen::Vector3d::UnitZ()).norm(), 1e-15);  // the tangential part is removed
  expect_orthonormal_right_handed(f);
  const Eigen::Vector3d d(0.3, -0.2, 0.9);
  EXPECT_LT((to_global(f, to_local(f, d)) - d).norm(), 1e-15);
  EXPECT_LT((to_local(f, d) - Eigen::Vector3d(0.1, d.dot(f.axes.col(1)) / 3.0, 0.3)).norm(), 1e-15);
}

TEST(LocalFrame, ACollapsedEdgeFallsBackToTheGlobalFrameAndTheReferenceLength) {
  const Eigen::Vector3d a(1, 2, 3);
  LocalFrame f = parent_edge_frame(a, a, Eigen::Vector3d::UnitZ(), 2.5, 1e-10);
  EXPECT_TRUE(f.degenerate);
  EXPECT_EQ(f.axes, Eigen::Matrix3d::Identity());
  EXPECT_EQ(f.scale, 2.5);
  f = parent_edge_frame(a, a + Eigen::Vector3d(1e-12, 0, 0), Eigen::Vector3d::UnitZ(), 2.5, 1e-10);
  EXPECT_TRUE(f.degenerate);
  f = parent_edge_frame(a, a, Eigen::Vector3d::Zero(), 0.0, 1e-10);  // everything collapsed
  EXPECT_TRUE(f.degenerate);
  EXPECT_EQ(f.scale, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  f = parent_edge_frame(a, Eigen::Vector3d(nan, 0, 0), Eigen::Vector3d::UnitZ(), 1.0, 1e-10);
  EXPECT_TRUE(f.degenerate);
  EXPECT_EQ(f.axes, Eigen::Matrix3d::Identity());
}

TEST(LocalFrame, AMissingNormalFallsBackToTheAxisLeastAlignedWithTheTangent) {
  const Eigen::Vector3d a(0, 0, 0), b(2, 0.2, 0.1);
  for (const Eigen::Vector3d& n : {Eigen::Vector3d::Zero().eval(), (3.0 * (b - a)).eval()}) {
    const LocalFrame f = parent_edge_frame(a, b, n, 1.0, 1e-10);
    EXPECT_TRUE(f.degenerate);
    EXPECT_DOUBLE_EQ(f.scale, (b - a).norm());
    EXPECT_LT((f.axes.col(0) - (b - a).normalized()).norm(), 1e-15);
    expect_orthonormal_right_handed(f);
    EXPECT_GT(f.axes.col(2).z(), 0.99);  // z is the axis least aligned with this tangent
  }
}

TEST(LocalFrame, AHierarchyWithACollapsedCoarseEdgeStillReconstructsExactly) {
  // Base: the icosahedron with vertex 1 moved onto vertex 0 (edge 0–1 collapsed, so its two
  // faces are degenerate). Synthesize random details, then analyze: the frames on the
  // collapsed edge use the fallback, identically in both directions.
  const TriMesh ico = icosahedron(10.0);
  const auto conn = subdivide_connectivity(ico.F, 12, 3);
  RowMatrixX3d base = ico.V;
  base.row(1) = base.row(0);
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 0.05);
  std::vector<RowMatrixX3d> details;
  for (int j = 1; j <= 3; ++j) {
    RowMatrixX3d D(conn.vertex_counts[j] - conn.vertex_counts[j - 1], 3);
    for (int i = 0; i < D.rows(); ++i)
      for (int k = 0; k < 3; ++k) D(i, k) = g(rng);
    details.push_back(D);
  }
  for (PredictScheme p : {PredictScheme::linear, PredictScheme::butterfly}) {
    WaveletOptions o;
    o.predict = p;
    const WaveletTransform wt(conn, o);
    const RowMatrixX3d fine = wt.synthesize(base, details);
    ASSERT_TRUE(fine.allFinite());
    const std::vector<LocalFrame> frames = wt.frames(0, base);
    int degenerate = 0;
    for (const LocalFrame& f : frames) {
      expect_orthonormal_right_handed(f);
      degenerate += f.degenerate ? 1 : 0;
    }
    EXPECT_GE(degenerate, 1);
    const WaveletAnalysis a = wt.analyze(fine);
    EXPECT_EQ(a.stats[0].degenerate_frames, degenerate);
    EXPECT_LE(max_row_distance(a.base, base), 1e-9 * bounding_box_diagonal(base));
    for (int j = 0; j < 3; ++j) EXPECT_LE(max_row_distance(a.details[j], details[j]), 1e-9) << "level " << j + 1;
    EXPECT_LE(max_row_distance(wt.synthesize(a.base, a.details), fine), 1e-9 * bounding_box_diagonal(fine));
  }
}

TEST(LocalFrame, AnalysisAndSynthesisBuildTheSameFrames) {
  const Hierarchy h = bumpy_sphere(3);
  const WaveletTransform wt(h.conn);
  const WaveletAnalysis a = wt.analyze(h.finest);
  for (int j = 0; j < 3; ++j) {
    // Synthesis receives S_j exactly as the analysis produced it, so its frames are bit-identical.
    const RowMatrixX3d S = wt.synthesize(a.base, a.details, j);
    const auto fa = wt.frames(j, a.levels[j]);
    const auto fs = wt.frames(j, S);
    double worst = 0;
    for (std::size_t i = 0; i < fa.size(); ++i) worst = std::max(worst, (fa[i].axes - fs[i].axes).norm());
    if (j == 0) {
      EXPECT_EQ(worst, 0.0);
    }
    EXPECT_LT(worst, 1e-12) << "level " << j;
  }
}
