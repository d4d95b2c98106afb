#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numeric>
#include <random>

#include "mesh/errors.h"
#include "tests/wavelets/hierarchies.h"
#include "wavelets/lifting.h"

using namespace mrsnake;
using namespace mrsnake::test;

namespace {

std::vector<WaveletOptions> all_option_sets() {
  std::vector<WaveletOptions> sets;
  for (PredictScheme p : {PredictScheme::linear, PredictScheme::butterfly})
    for (bool update : {false, true})
      for (DetailFrame frame : {DetailFrame::global, DetailFrame::local}) {
        WaveletOptions o;
        o.predict = p;
        o.update = update;
        o.frame = frame;
        sets.push_back(o);
      }
  return sets;
}

std::string describe(const WaveletOptions& o) {
  return to_string(o.predict) + (o.update ? "+update" : "") + "/" + to_string(o.frame);
}

}  // namespace

TEST(Lifting, SynthesisOfAnalysisIsTheInputOnEveryTestMesh) {
  for (const Hierarchy& h : all_hierarchies(4)) {
    const double diag = bounding_box_diagonal(h.finest);
    for (const WaveletOptions& o : all_option_sets()) {
      const WaveletTransform wt(h.conn, o);
      const WaveletAnalysis a = wt.analyze(h.finest);
      ASSERT_EQ(a.base.rows(), h.conn.vertex_counts[0]);
      ASSERT_EQ(a.details.size(), 4u);
      const RowMatrixX3d S = wt.synthesize(a.base, a.details);
      EXPECT_LE(max_row_distance(S, h.finest), 1e-9 * diag) << h.name << " " << describe(o);
      // Every intermediate level too.
      for (int j = 0; j <= 4; ++j)
        EXPECT_LE(max_row_distance(wt.synthesize(a.base, a.details, j), a.levels[j]), 1e-9 * diag)
            << h.name << " " << describe(o) << " level " << j;
    }
  }
}

TEST(Lifting, SingleLevelStepsEqualTheFullSynthesis) {
  const Hierarchy h = bumpy_cap(4);
  const WaveletTransform wt(h.conn);
  const WaveletAnalysis a = wt.analyze(h.finest);
  RowMatrixX3d S = a.base;
  for (int j = 0; j < 4; ++j) S = wt.synthesize_level(j, S, a.details[j]);
  EXPECT_EQ(S, wt.synthesize(a.base, a.details));  // bit for bit: the same steps
  // And each single analysis step is the inverse of the single synthesis step.
  for (int j = 0; j < 4; ++j) {
    const auto step = wt.analyze_level(j, a.levels[j + 1]);
    EXPECT_EQ(step.coarse, a.levels[j]);
    EXPECT_EQ(step.details, a.details[j]);
    EXPECT_LE(max_row_distance(wt.synthesize_level(j, step.coarse, step.details), a.levels[j + 1]), 1e-12);
  }
}

TEST(Lifting, LocalDetailsFollowASimilarityOfTheCoarseLevel) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(12.0, -7.5, 30.0);
  const double s = 1.7;
  const auto move = [&](const RowMatrixX3d& V) {
    RowMatrixX3d W = (s * V * R.transpose()).rowwise() + t;
    return W;
  };
  for (const Hierarchy& h : all_hierarchies(4)) {
    for (PredictScheme p : {PredictScheme::linear, PredictScheme::butterfly}) {
      WaveletOptions o;
      o.predict = p;
      const WaveletTransform wt(h.conn, o);
      const WaveletAnalysis a = wt.analyze(h.finest);
      const RowMatrixX3d moved_fine = move(h.finest);
      const RowMatrixX3d S = wt.synthesize(move(a.base), a.details);
      EXPECT_LE(max_row_distance(S, moved_fine), 1e-9 * bounding_box_diagonal(moved_fine))
          << h.name << " " << to_string(p);
      for (const DetailStats& st : a.stats) EXPECT_EQ(st.degenerate_frames, 0) << h.name;

      // The same test fails with global details: the check can tell them apart.
      o.frame = DetailFrame::global;
      const WaveletTransform wg(h.conn, o);
      const WaveletAnalysis g = wg.analyze(h.finest);
      EXPECT_GT(max_row_distance(wg.synthesize(move(g.base), g.details), moved_fine),
                1e-4 * bounding_box_diagonal(moved_fine));
    }
  }
}

TEST(Lifting, DetailEnergyShrinksWithTheLevelOnSmoothShapes) {
  for (const Hierarchy& h : {bumpy_sphere(5), ellipsoid(5), bumpy_cap(5), height_field_fan(6, 5)}) {
    for (PredictScheme p : {PredictScheme::linear, PredictScheme::butterfly}) {
      WaveletOptions o;
      o.predict = p;
      const WaveletAnalysis a = WaveletTransform(h.conn, o).analyze(h.finest);
      ASSERT_EQ(a.stats.size(), 5u);
      for (std::size_t j = 0; j < a.stats.size(); ++j) {
        EXPECT_EQ(a.stats[j].level, static_cast<int>(j) + 1);
        EXPECT_EQ(a.stats[j].count, h.conn.vertex_counts[j + 1] - h.conn.vertex_counts[j]);
        EXPECT_NEAR(a.stats[j].rms, std::sqrt(a.stats[j].energy / a.stats[j].count), 1e-12);
        if (j > 0) {
          EXPECT_LT(a.stats[j].rms, 0.6 * a.stats[j - 1].rms) << h.name << " " << to_string(p) << " level " << j + 1;
        }
      }
    }
  }
}

TEST(Lifting, ButterflyNormalDetailsAreMuchSmallerThanLinearOnSmoothShapes) {
  // The shape information is the normal part of the local details (component 2). The
  // tangential part mostly records how the surface is sampled, which the icosphere's
  // projected midpoints and the fan's polygon corners make irregular for a 10-point stencil.
  for (const Hierarchy& h : {bumpy_sphere(5), bumpy_cap(5), height_field_fan(6, 5)}) {
    WaveletOptions lin, but;
    lin.predict = PredictScheme::linear;
    const auto a_lin = WaveletTransform(h.conn, lin).analyze(h.finest);
    const auto a_but = WaveletTransform(h.conn, but).analyze(h.finest);
    const auto normal_rms = [](const RowMatrixX3d& D) { return std::sqrt(D.col(2).squaredNorm() / D.rows()); };
    for (int j : {3, 4}) {
      EXPECT_LT(normal_rms(a_but.details[j]), 0.15 * normal_rms(a_lin.details[j])) << h.name << " level " << j + 1;
      // Linear normal details halve per level (relative to the edge length); butterfly's shrink faster.
      EXPECT_LT(normal_rms(a_but.details[j]), 0.45 * normal_rms(a_but.details[j - 1])) << h.name << " level " << j + 1;
    }
  }
}

TEST(Lifting, UpdateMakesTheCoarseLevelALowPassApproximation) {
  // A noisy sphere: the lifted coarse levels are closer to the smooth sphere than the
  // plain subsamples of the noisy finest level.
  const TriMesh ico = icosahedron();
  const auto conn = subdivide_connectivity(ico.F, 12, 5);
  RowMatrixX3d V = sphere_directions(conn, ico.V) * 10.0;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.05);
  for (int v = 0; v < V.rows(); ++v)
    for (int k = 0; k < 3; ++k) V(v, k) += noise(rng);
  const auto radial_rms = [](const RowMatrixX3d& W) {
    return std::sqrt((W.rowwise().norm().array() - 10.0).square().mean());
  };
  for (PredictScheme p : {PredictScheme::linear, PredictScheme::butterfly}) {
    WaveletOptions lifted, plain;
    lifted.predict = plain.predict = p;
    plain.update = false;
    const auto a = WaveletTransform(conn, lifted).analyze(V);
    const auto b = WaveletTransform(conn, plain).analyze(V);
    for (int j : {3, 4}) {
      EXPECT_LT(radial_rms(a.levels[j]), 0.8 * radial_rms(b.levels[j])) << to_string(p) << " level " << j;
    }
    // The mean position is kept on this regular closed mesh, apart from its 12 valence-5 vertices.
    EXPECT_LT((a.levels[3].colwise().mean() - V.colwise().mean()).norm(), 0.01);
  }
}

TEST(Lifting, StencilsAreAffineAndFollowTheRules) {
  for (const Hierarchy& h : all_hierarchies(2)) {
    const WaveletTransform wt(h.conn);
    for (int j = 0; j < 2; ++j)
      for (int v = h.conn.vertex_counts[j]; v < h.conn.vertex_counts[j + 1]; ++v) {
        const PredictStencil s = wt.predict_stencil(j, v);
        EXPECT_NEAR(std::accumulate(s.weights.begin(), s.weights.end(), 0.0), 1.0, 1e-14) << h.name;
      }
  }
  // On the hexagonal fan: a boundary edge uses the 4-point rule, a spoke the k = 6 stencil
  // of the center, and an interior edge between regular vertices at level 1 the 10-point stencil.
  const Hierarchy fan = height_field_fan(6, 2);
  const WaveletTransform wt(fan.conn);
  int four_point = 0, ten_point = 0, center = 0;
  for (int j = 0; j < 2; ++j)
    for (int v = fan.conn.vertex_counts[j]; v < fan.conn.vertex_counts[j + 1]; ++v) {
      const PredictStencil s = wt.predict_stencil(j, v);
      if (s.weights.size() == 4) {
        EXPECT_DOUBLE_EQ(s.weights[0], -1.0 / 16);
        EXPECT_DOUBLE_EQ(s.weights[1], 9.0 / 16);
        ++four_point;
      } else if (s.weights.size() == 8) {
        EXPECT_DOUBLE_EQ(s.weights[0], 0.5);
        EXPECT_DOUBLE_EQ(s.weights[2], 0.125);
        EXPECT_DOUBLE_EQ(s.weights[7], -1.0 / 16);
        ++ten_point;
      } else if (s.weights.size() == 7 && s.indices[0] == 0) {
        EXPECT_DOUBLE_EQ(s.weights[0], 0.75);
        ++center;
      }
    }
  EXPECT_EQ(four_point, 6 + 12);  // boundary edges of levels 0 and 1
  EXPECT_EQ(center, 6);           // level-0 spokes (the center and the boundary); level 1 spokes are 10-point
  EXPECT_GT(ten_point, 0);
}

TEST(Lifting, ButterflyReproducesCubicsOnARegularGrid) {
  // An equilateral lattice patch; z a cubic polynomial of (x, y). The 10-point butterfly
  // reproduces cubics, so every new vertex between two interior vertices gets a zero detail.
  const int N = 8;
  RowMatrixX3d V0((N + 1) * (N + 1), 3);
  std::vector<Eigen::RowVector3i> tris;
  for (int j = 0; j <= N; ++j)
    for (int i = 0; i <= N; ++i) V0.row(j * (N + 1) + i) << i + 0.5 * j, j * std::sqrt(3.0) / 2.0, 0.0;
  for (int j = 0; j < N; ++j)
    for (int i = 0; i < N; ++i) {
      const int a = j * (N + 1) + i;
      tris.emplace_back(a, a + 1, a + N + 1);
      tris.emplace_back(a + 1, a + N + 2, a + N + 1);
    }
  RowMatrixX3i F(static_cast<int>(tris.size()), 3);
  for (std::size_t f = 0; f < tris.size(); ++f) F.row(static_cast<int>(f)) = tris[f];
  const auto conn = subdivide_connectivity(F, static_cast<int>(V0.rows()), 1);
  RowMatrixX3d V = midpoint_refine(conn, 0, V0);
  for (int v = 0; v < V.rows(); ++v) {
    const double x = V(v, 0), y = V(v, 1);
    V(v, 2) = 0.3 * x * x * x - 0.2 * x * x * y + 0.1 * y * y * y + x * y - 2.0 * x + 1.0;
  }
  // Interior vertices: not on the border of the lattice.
  const auto interior = [&](int v) {
    const int i = v % (N + 1), j = v / (N + 1);
    return i > 0 && j > 0 && i < N && j < N;
  };
  WaveletOptions o;
  o.frame = DetailFrame::global;
  const auto step = WaveletTransform(conn, o).analyze_level(0, V);
  int checked = 0;
  for (int v = conn.vertex_counts[0]; v < conn.vertex_counts[1]; ++v) {
    const auto p = conn.parents(v);
    if (!interior(p[0]) || !interior(p[1])) continue;
    EXPECT_LT(step.details.row(v - conn.vertex_counts[0]).norm(), 1e-10) << "vertex " << v;
    ++checked;
  }
  EXPECT_GT(checked, 100);
  // The linear predictor does not reproduce them.
  o.predict = PredictScheme::linear;
  EXPECT_GT(WaveletTransform(conn, o).analyze_level(0, V).details.rowwise().norm().maxCoeff(), 1e-3);
}

TEST(Lifting, ExtraordinaryStencilsReproduceAffineFunctionsOnARegularFan) {
  // On the affine image of a planar regular k-gon fan refined by midpoints, every spoke's
  // prediction is exact: Zorin's weights reproduce linear functions.
  Eigen::Matrix3d A;
  A << 1.2, 0.3, -0.4, 0.1, 0.9, 0.5, -0.2, 0.7, 1.1;
  for (int k : {3, 4, 5, 6, 7, 8, 9}) {
    RowMatrixX3d V0(k + 1, 3);
    RowMatrixX3i F(k, 3);
    V0.row(0).setZero();
    for (int i = 0; i < k; ++i) {
      V0.row(i + 1) << std::cos(2 * M_PI * i / k), std::sin(2 * M_PI * i / k), 0.0;
      F.row(i) << 0, i + 1, (i + 1) % k + 1;
    }
    const auto conn = subdivide_connectivity(F, k + 1, 1);
    const RowMatrixX3d V = (midpoint_refine(conn, 0, V0) * A.transpose()).rowwise() + Eigen::RowVector3d(1, 2, 3);
    WaveletOptions o;
    o.frame = DetailFrame::global;
    const WaveletTransform wt(conn, o);
    const auto step = wt.analyze_level(0, V);
    int spokes = 0;
    for (int v = k + 1; v < conn.vertex_counts[1]; ++v) {
      if (conn.parents(v).minCoeff() != 0) continue;
      EXPECT_LT(step.details.row(v - k - 1).norm(), 1e-13) << "k = " << k;
      EXPECT_DOUBLE_EQ(wt.predict_stencil(0, v).weights[0], 0.75);
      ++spokes;
    }
    EXPECT_EQ(spokes, k);
  }
}

TEST(Lifting, RefusesAConnectivityThatIsNotA1to4Split) {
  const TriMesh ico = icosahedron();
  auto conn = subdivide_connectivity(ico.F, 12, 2);
  conn.faces[1](3, 0) = 0;  // the middle child of face 0 now lists a corner
  EXPECT_THROW(WaveletTransform{conn}, TopologyError);
}
