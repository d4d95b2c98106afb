#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "mesh/quality.h"
#include "tests/test_support.h"

using namespace mrsnake;

namespace {

TriMesh single_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  TriMesh m;
  m.V.resize(3, 3);
  m.V.row(0) = a;
  m.V.row(1) = b;
  m.V.row(2) = c;
  m.F.resize(1, 3);
  m.F << 0, 1, 2;
  return m;
}

}  // namespace

TEST(Quality, EquilateralTriangleIsOne) {
  const Eigen::Vector3d a(0, 0, 0), b(2, 0, 0), c(1, std::sqrt(3.0), 0);
  EXPECT_NEAR(frey_borouchaki_quality(a, b, c), 1.0, 1e-12);
  EXPECT_NEAR(radius_ratio(a, b, c), 1.0, 1e-12);
  // Invariant under scaling and rigid motion.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d t(5, -3, 2);
  EXPECT_NEAR(frey_borouchaki_quality(7 * R * a + t, 7 * R * b + t, 7 * R * c + t), 1.0, 1e-12);
  EXPECT_NEAR(radius_ratio(7 * R * a + t, 7 * R * b + t, 7 * R * c + t), 1.0, 1e-12);

  const QualityReport q = mesh_quality(single_triangle(a, b, c));
  EXPECT_NEAR(q.min_angle_deg, 60.0, 1e-9);
  EXPECT_NEAR(q.angle_deviation_deg, 0.0, 1e-9);
  EXPECT_NEAR(q.angle_variance_deg2, 0.0, 1e-9);
  EXPECT_NEAR(q.edge_length_mean, 2.0, 1e-12);
  EXPECT_NEAR(q.edge_length_cv, 0.0, 1e-12);
  EXPECT_EQ(q.pct_min_angle_below_30, 0.0);
  // Three boundary vertices of valence 2, no interior vertex.
  EXPECT_EQ(q.pct_valence6_interior, 0.0);
  EXPECT_EQ(q.pct_valence4_boundary, 0.0);
}

TEST(Quality, RightIsoscelesTriangleAnalytic) {
  // Legs 1, hypotenuse √2: A = 1/2, half-perimeter p = (2 + √2)/2 = 1 + √2/2, longest h = √2.
  //   Q = (6/√3)·A/(p·h) = (3/√3)/(√2 + 1) = √3/(√2 + 1) = √3·(√2 − 1) ≈ 0.717439.
  //   r_in = A/p = 1/(2 + √2) = (2 − √2)/2, r_circ = h/2 = √2/2 (hypotenuse is a diameter),
  //   2·r_in/r_circ = (2 − √2)·2/√2 = 2√2 − 2 ≈ 0.828427.
  // Angles 90°, 45°, 45°: deviation from 60° = (30 + 15 + 15)/3 = 20°, variance about the
  // mean 60° = (900 + 225 + 225)/3 = 450 deg².
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const double q_expected = std::sqrt(3.0) * (std::sqrt(2.0) - 1.0);
  const double rho_expected = 2.0 * std::sqrt(2.0) - 2.0;
  EXPECT_NEAR(frey_borouchaki_quality(a, b, c), q_expected, 1e-12);
  EXPECT_NEAR(radius_ratio(a, b, c), rho_expected, 1e-12);
  EXPECT_NEAR(q_expected, 0.717439, 1e-6);
  EXPECT_NEAR(rho_expected, 0.828427, 1e-6);

  const QualityReport q = mesh_quality(single_triangle(a, b, c));
  EXPECT_NEAR(q.q_min, q_expected, 1e-12);
  EXPECT_NEAR(q.q_mean, q_expected, 1e-12);
  EXPECT_NEAR(q.radius_ratio_min, rho_expected, 1e-12);
  EXPECT_NEAR(q.min_angle_deg, 45.0, 1e-9);
  EXPECT_NEAR(q.mean_min_angle_deg, 45.0, 1e-9);
  EXPECT_NEAR(q.angle_deviation_deg, 20.0, 1e-9);
  EXPECT_NEAR(q.angle_variance_deg2, 450.0, 1e-9);
  // Edge lengths 1, 1, √2.
  const double mean = (2.0 + std::sqrt(2.0)) / 3.0;
  const double var = (2 * std::pow(1 - mean, 2) + std::pow(std::sqrt(2.0) - mean, 2)) / 3.0;
  EXPECT_NEAR(q.edge_length_mean, mean, 1e-12);
  EXPECT_NEAR(q.edge_length_cv, std::sqrt(var) / mean, 1e-12);
  EXPECT_NEAR(q.edge_length_variance, var / (mean * mean), 1e-12);
}

TEST(Quality, DegenerateTriangleIsZero) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0), c(2, 0, 0);
  EXPECT_EQ(frey_borouchaki_quality(a, b, c), 0.0);
  EXPECT_EQ(radius_ratio(a, b, c), 0.0);
  EXPECT_EQ(frey_borouchaki_quality(a, a, a), 0.0);
  EXPECT_EQ(radius_ratio(a, a, a), 0.0);
  EXPECT_THROW(mesh_quality(TriMesh{}), InputError);
}

TEST(Quality, IcosahedronAllValenceFiveAllSixtyDegrees) {
  const QualityReport q = mesh_quality(icosahedron(3.0));
  EXPECT_EQ(q.vertices, 12);
  EXPECT_EQ(q.faces, 20);
  EXPECT_EQ(q.pct_valence6_interior, 0.0);
  EXPECT_EQ(q.pct_valence4_boundary, 0.0);  // closed
  EXPECT_NEAR(q.min_angle_deg, 60.0, 1e-9);
  EXPECT_NEAR(q.mean_min_angle_deg, 60.0, 1e-9);
  EXPECT_NEAR(q.angle_deviation_deg, 0.0, 1e-9);
  EXPECT_NEAR(q.angle_variance_deg2, 0.0, 1e-9);
  EXPECT_NEAR(q.q_min, 1.0, 1e-12);
  EXPECT_NEAR(q.q_mean, 1.0, 1e-12);
  EXPECT_NEAR(q.radius_ratio_min, 1.0, 1e-12);
  EXPECT_NEAR(q.edge_length_cv, 0.0, 1e-12);
  EXPECT_NEAR(q.edge_length_variance, 0.0, 1e-12);
  EXPECT_NEAR(q.area_cv, 0.0, 1e-12);
  // Edge of the icosahedron inscribed in radius R: R·4/√(10 + 2√5).
  EXPECT_NEAR(q.edge_length_mean, 3.0 * 4.0 / std::sqrt(10.0 + 2.0 * std::sqrt(5.0)), 1e-12);
}

TEST(Quality, IcosphereValenceSixPercentage) {
  // Level 4: 10·4⁴ + 2 = 2562 vertices, of which only the 12 icosahedron corners have valence 5.
  const QualityReport q = mesh_quality(icosphere(4));
  EXPECT_EQ(q.vertices, 2562);
  EXPECT_EQ(q.faces, 5120);
  EXPECT_DOUBLE_EQ(q.pct_valence6_interior, 100.0 * 2550.0 / 2562.0);
  EXPECT_GT(q.min_angle_deg, 45.0);  // projected midpoint subdivision stays close to equilateral
  EXPECT_GT(q.q_min, 0.85);
  EXPECT_LT(q.q_mean, 1.0);
}

TEST(Quality, HexagonFanInteriorAndBoundaryValence) {
  // A regular hexagon split into 6 equilateral triangles: the centre is interior with
  // valence 6, the 6 rim vertices are boundary with valence 3.
  TriMesh m;
  m.V.resize(7, 3);
  m.V.row(0) << 0, 0, 0;
  for (int k = 0; k < 6; ++k) m.V.row(k + 1) << std::cos(k * M_PI / 3), std::sin(k * M_PI / 3), 0;
  m.F.resize(6, 3);
  for (int k = 0; k < 6; ++k) m.F.row(k) << 0, k + 1, (k + 1) % 6 + 1;
  QualityReport q = mesh_quality(m);
  EXPECT_EQ(q.pct_valence6_interior, 100.0);
  EXPECT_EQ(q.pct_valence4_boundary, 0.0);
  EXPECT_NEAR(q.q_min, 1.0, 1e-12);

  // Drop one triangle: the centre becomes a boundary vertex of valence 6, rim ends valence 2.
  // Boundary valences: centre 6, two ends 2, four others 3 -> none of valence 4.
  m.F.conservativeResize(5, 3);
  q = mesh_quality(m);
  EXPECT_EQ(q.pct_valence6_interior, 0.0);  // no interior vertex left
  EXPECT_EQ(q.pct_valence4_boundary, 0.0);
}

TEST(Quality, StripBoundaryValenceFour) {
  // A regular triangulated strip of 2 rows × 5 columns of vertices: the 6 middle boundary
  // vertices have valence 4 (the 4 corners have 2 or 3).
  TriMesh m;
  const int cols = 5;
  m.V.resize(2 * cols, 3);
  for (int i = 0; i < cols; ++i) {
    m.V.row(i) << i, 0, 0;
    m.V.row(cols + i) << i + 0.5, std::sqrt(3.0) / 2, 0;
  }
  m.F.resize(2 * (cols - 1), 3);
  for (int i = 0; i < cols - 1; ++i) {
    m.F.row(2 * i) << i, i + 1, cols + i;
    m.F.row(2 * i + 1) << i + 1, cols + i + 1, cols + i;
  }
  const QualityReport q = mesh_quality(m);
  EXPECT_DOUBLE_EQ(q.pct_valence4_boundary, 60.0);
  EXPECT_NEAR(q.min_angle_deg, 60.0, 1e-9);
}

TEST(Quality, JsonKeysAreTheFieldNames) {
  const nlohmann::json j = mesh_quality(icosahedron());
  for (const char* key :
       {"vertices", "faces", "min_angle_deg", "mean_min_angle_deg", "pct_min_angle_below_30", "angle_deviation_deg",
        "angle_variance_deg2", "q_min", "q_mean", "radius_ratio_min", "radius_ratio_mean", "edge_length_mean",
        "edge_length_cv", "edge_length_variance", "pct_valence6_interior", "pct_valence4_boundary", "area_cv"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j.size(), 17u);
  EXPECT_EQ(j["faces"].get<int>(), 20);
}

TEST(QualityCommand, JsonOutputAndMissingFile) {
  const auto dir = test::scratch_dir("quality-cli");
  const std::string mesh = (dir / "sphere.off").string();
  write_mesh(mesh, icosphere(3, 5.0));
  auto r = test::run_mrsnake("-q quality " + mesh + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  nlohmann::json j = nlohmann::json::parse(r.output);
  EXPECT_EQ(j["faces"].get<int>(), 1280);
  EXPECT_DOUBLE_EQ(j["pct_valence6_interior"].get<double>(), 100.0 * 630.0 / 642.0);
  EXPECT_FALSE(j.contains("distance"));

  r = test::run_mrsnake("-q quality " + mesh + " --reference " + mesh + " --samples 3 --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  j = nlohmann::json::parse(r.output);
  ASSERT_TRUE(j.contains("distance"));
  EXPECT_LT(j["distance"]["hausdorff_mm"].get<double>(), 1e-9);
  EXPECT_GT(j["distance"]["reference_diagonal_mm"].get<double>(), 9.0);

  r = test::run_mrsnake("quality " + mesh);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("Q min"), std::string::npos) << r.output;

  r = test::run_mrsnake("quality " + (dir / "missing.off").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  r = test::run_mrsnake("quality " + mesh + " --reference " + (dir / "missing.vtp").string());
  EXPECT_EQ(r.exit_code, 3) << r.output;
  r = test::run_mrsnake("quality");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  std::filesystem::remove_all(dir);
}
