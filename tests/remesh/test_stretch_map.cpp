// The hierarchical sphere map (remesh/stretch_map.h): on a shape whose one-chart conformal map
// squeezes past what doubles resolve, it must embed every triangle and bound the squeeze, and
// the remesher must fall back to it and build every level without a flip in D.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "mesh/errors.h"
#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "remesh/base_mesh.h"
#include "remesh/parameterization.h"
#include "remesh/remesh.h"
#include "remesh/stretch_map.h"
#include "tests/remesh/remesh_shapes.h"

using namespace mrsnake;

namespace {

// log10 of the largest over the smallest area ratio A3D / A_D of the faces.
double area_stretch_spread_log10(const TriMesh& mesh, const RowMatrixX3d& D) {
  double lo = INFINITY, hi = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d p = D.row(mesh.F(f, 0)), q = D.row(mesh.F(f, 1)), r = D.row(mesh.F(f, 2));
    const double ratio = (b - a).cross(c - a).norm() / (q - p).cross(r - p).norm();
    lo = std::min(lo, ratio);
    hi = std::max(hi, ratio);
  }
  return std::log10(hi / lo);
}

// The unit octahedron: +x, -x, +y, -y, +z, -z.
RowMatrixX3d octahedron_vertices() {
  RowMatrixX3d V(6, 3);
  V << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  return V;
}

RowMatrixX3i octahedron_faces() {
  RowMatrixX3i F(8, 3);
  F << 0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5;
  return F;
}

// The octahedron with ±y tilted toward +x+z, so that the quad around the edge +z/+x is
// strictly convex in D.
RowMatrixX3d tilted_octahedron() {
  RowMatrixX3d D = octahedron_vertices();
  D.row(2) = Eigen::RowVector3d(0.5, 1, 0.5).normalized();
  D.row(3) = Eigen::RowVector3d(0.5, -1, 0.5).normalized();
  return D;
}

// Whether some face of F has the directed edge a -> b.
bool has_edge(const RowMatrixX3i& F, int a, int b) {
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      if (F(f, k) == a && F(f, (k + 1) % 3) == b) return true;
  return false;
}

}  // namespace

TEST(HierarchicalMap, ACapsuleTooLongForOneChartEmbedsWithItsSqueezeBounded) {
  const TriMesh tube = test::capsule(30.0);
  ASSERT_TRUE(topology_report(tube).is_closed_genus0());
  ParameterizationOptions punctured;
  punctured.sphere_map = SphereMap::punctured;
  EXPECT_THROW(parameterize(tube, punctured), AlgorithmError);  // the one-chart map cannot

  const RowMatrixX3d D = hierarchical_sphere_map(tube);
  ASSERT_EQ(D.rows(), tube.num_vertices());
  EXPECT_LT((D.rowwise().norm().array() - 1).abs().maxCoeff(), 1e-12);  // on the unit sphere
  EXPECT_EQ(count_flipped(D, tube.F), 0);
  // A conformal map's area ratio along a tube of 30 radii falls by ~e^-60 (26 orders).
  EXPECT_LT(area_stretch_spread_log10(tube, D), 5.0);
}

TEST(HierarchicalMap, OfASphereIsNearlyASimilarity) {
  const TriMesh sphere = icosphere(3);
  const RowMatrixX3d D = hierarchical_sphere_map(sphere);
  EXPECT_EQ(count_flipped(D, sphere.F), 0);
  EXPECT_LT(normalized_stretch(sphere, D), 1.05);
  EXPECT_LT(area_stretch_spread_log10(sphere, D), 0.5);
}

// A squeeze is a stretch past 12 orders of magnitude, flips or not; flips alone are none.
TEST(HierarchicalMap, AOneChartMapIsSqueezedPastTwelveOrdersOfMagnitude) {
  const auto failure = [](int flipped, double spread) { return OneChartFailure{flipped, spread}; };
  EXPECT_FALSE(failure(1, 4.7).squeezed());
  EXPECT_FALSE(failure(0, 12.0).squeezed());
  EXPECT_TRUE(failure(0, 12.5).squeezed());
  EXPECT_TRUE(failure(1955, std::numeric_limits<double>::infinity()).squeezed());
  EXPECT_TRUE(failure(3, std::numeric_limits<double>::quiet_NaN()).squeezed());  // not measurable
}

// The reason names what failed: the flips, the squeeze (past what doubles measure, if so), or
// both. A squeezed octopus-like shape flips too, and the report must not name only the flips.
TEST(HierarchicalMap, AFailedOneChartMapSaysWhetherItFlippedOrWasSqueezedOrBoth) {
  const double infinite = std::numeric_limits<double>::infinity();
  EXPECT_EQ((OneChartFailure{1, 4.7}.reason()), "the one-chart map flipped 1 triangles");
  EXPECT_EQ((OneChartFailure{0, 17.1}.reason()), "the one-chart map's area stretch spans 17 orders of magnitude");
  EXPECT_EQ((OneChartFailure{0, infinite}.reason()),
            "the one-chart map's area stretch spans more orders of magnitude than doubles measure");
  EXPECT_EQ((OneChartFailure{1955, infinite}.reason()),
            "the one-chart map flipped 1955 triangles, and its area stretch spans more orders of magnitude than "
            "doubles measure");
}

TEST(HierarchicalMap, TheAutomaticSphereMapFallsBackToItAndEveryLevelIsFlipFree) {
  const TriMesh tube = test::capsule(30.0);
  ParameterizationOptions told;
  int fallbacks = 0;
  OneChartFailure failure;
  told.on_hierarchical_fallback = [&](const OneChartFailure& f) {
    ++fallbacks;
    failure = f;
    return true;
  };
  const Parameterization param = parameterize(tube, told);
  EXPECT_EQ(fallbacks, 1);  // the automatic domain starts the base-mesh route on it
  EXPECT_TRUE(failure.squeezed()) << failure.stretch_spread_log10;  // a tube 30 radii long
  EXPECT_EQ(param.summary.value("sphere_map_fallback", std::string()), "hierarchical: " + failure.reason());
  EXPECT_EQ(parameterize(icosphere(3), told).sphere_map, SphereMap::punctured);
  EXPECT_EQ(fallbacks, 1);  // no fallback, no call
  EXPECT_EQ(param.sphere_map, SphereMap::hierarchical);
  EXPECT_EQ(param.summary["sphere_map"], "hierarchical");
  EXPECT_NE(param.summary.value("sphere_map_fallback", std::string()).find("hierarchical: the one-chart map"),
            std::string::npos);
  // Declined, the hierarchical map is not built: the parameterization stops there.
  told.on_hierarchical_fallback = [](const OneChartFailure&) { return false; };
  EXPECT_THROW(parameterize(tube, told), AlgorithmError);

  RemeshOptions options;
  options.domain = ParameterDomain::sphere;  // the sphere route alone (the default also tries the base mesh)
  options.target_faces = 2048;
  const RemeshResult result = remesh(tube, options);
  ASSERT_EQ(result.parameterization["sphere_map"], "hierarchical");
  for (int j = 0; j <= result.connectivity.levels(); ++j) {
    EXPECT_EQ(result.levels[j].flipped_triangles, 0) << "level " << j;
    EXPECT_EQ(count_flipped(result.levels[j].domain_positions, result.connectivity.faces[j]), 0) << "level " << j;
  }
  EXPECT_EQ(result.levels.back().positions.rows(), result.connectivity.vertex_count(result.connectivity.levels()));
  // Every vertex of the finest level lies within the tube's radius of its axis segment.
  const RowMatrixX3d& X = result.levels.back().positions;
  for (int v = 0; v < X.rows(); ++v) {
    const double z = std::clamp(X(v, 2), 0.0, 30.0);
    EXPECT_LT((X.row(v) - Eigen::RowVector3d(0, 0, z)).norm(), 1.05) << v;
  }
}

// A tube 60 radii long: the bend bound (remesh/sizing.h) asks for more base vertices than a
// 2k-face hierarchy's base of 66 has, so the base grows 4x and the hierarchy loses a level. On
// the larger base, around and along the tube, the triangles are rounder and closer to it.
TEST(BendBound, ALongTubeGrowsTheBaseAndTheTrianglesGetRounder) {
  const TriMesh tube = test::capsule(60.0);
  RemeshOptions options;
  options.domain = ParameterDomain::sphere;  // the sphere route's base (the default also tries the base mesh)
  options.target_faces = 2048;
  RemeshOptions unbounded = options;
  unbounded.base.max_bend = 0;
  const RemeshResult grown = remesh(tube, options);
  const RemeshResult plain = remesh(tube, unbounded);
  EXPECT_EQ(plain.parameterization["base_vertices"], 66);
  EXPECT_EQ(grown.parameterization["base_vertices"], 4 * 66 - 6);
  EXPECT_EQ(grown.connectivity.levels(), plain.connectivity.levels() - 1);
  const nlohmann::json& g = grown.levels.back().stats;
  const nlohmann::json& p = plain.levels.back().stats;
  EXPECT_EQ(g["faces"], p["faces"]);
  EXPECT_EQ(g["flipped_triangles"], 0);
  // Measured: Q mean 0.43 -> 0.69, Hausdorff 0.98 -> 0.19 % of the diagonal.
  EXPECT_GT(g["quality"]["q_mean"].get<double>(), p["quality"]["q_mean"].get<double>() + 0.15);
  EXPECT_LT(g["distance"]["hausdorff_pct"].get<double>(), 0.5 * p["distance"]["hausdorff_pct"].get<double>());
}

TEST(BaseMeshFlips, NoValenceFlipLeavesAnInteriorVertexWithThreeEdges) {
  // A bipyramid over a 10-gon: the poles have 10 edges, the equator vertices 4. Flipping a
  // pole's edge to the equator would lower sum (valence - 6)² by 8 (the pole 10 -> 9, two
  // equator vertices 4 -> 5) but leave the third with three edges, and three triangles at every
  // level with an angle near 120° each; flipping an equator edge would leave two such vertices.
  // Nothing is flipped, with every flip allowed.
  const int m = 10;
  RowMatrixX3i B(2 * m, 3);
  for (int i = 0; i < m; ++i) {
    B.row(i) << m, i, (i + 1) % m;
    B.row(m + i) << m + 1, (i + 1) % m, i;
  }
  const RowMatrixX3i before = B;
  EXPECT_EQ(flip_toward_regular_valence(m + 2, B, 3, [](const EdgeFlip&) { return true; }), 0);
  EXPECT_EQ(B, before);
}

TEST(BaseMeshFlips, AnEdgeFacingTwoObtuseSurfaceAnglesIsFlippedWhereDAllows) {
  // An octahedron in D with ±y tilted toward +x+z, so that the quad around the edge +z/+x is
  // strictly convex. On the surface, ±y sit next to that edge's midpoint: the two angles facing
  // it are about 164° each, and the surface's Delaunay triangulation has the edge +y/-y instead.
  const RowMatrixX3d octahedron = octahedron_vertices();
  const RowMatrixX3d D = tilted_octahedron();
  RowMatrixX3i F = octahedron_faces();
  ASSERT_EQ(count_flipped(D, F), 0);
  RowMatrixX3d X = D;
  X.row(2) << 0.5, 0.1, 0.5;
  X.row(3) << 0.5, -0.1, 0.5;
  EXPECT_GE(flip_toward_surface_delaunay(D, X, F), 1);
  EXPECT_EQ(count_flipped(D, F), 0);
  EXPECT_TRUE(has_edge(F, 2, 3));
  // On the octahedron itself every angle is 60°: nothing to flip.
  RowMatrixX3i G = octahedron_faces();
  EXPECT_EQ(flip_toward_surface_delaunay(octahedron, octahedron, G), 0);
  // With ±y antipodal in D, the new faces would lie on a great circle: D forbids the flip.
  EXPECT_EQ(flip_toward_surface_delaunay(octahedron, X, G), 0);
}

TEST(BaseMeshFlips, AMarginLeavesEdgesOnlyJustPastDelaunay) {
  // The octahedron of the test above, with ±y at distance t from the midpoint of the edge
  // +x/+z (half length h = √2/2), square to it: the two angles facing that edge sum to
  // 4·atan(h / t). At 190° the edge flips with a margin of 5° and stays with one of 15°; at
  // 200° it flips with 15° too.
  const double pi = 3.14159265358979323846, h = std::sqrt(0.5), degree = pi / 180;
  const RowMatrixX3d D = tilted_octahedron();
  const auto joins_y_poles = [&](double facing_sum_deg, double margin_deg) {
    RowMatrixX3i F = octahedron_faces();
    const double t = h / std::tan(facing_sum_deg * degree / 4);
    RowMatrixX3d X = D;
    X.row(2) << 0.5, t, 0.5;
    X.row(3) << 0.5, -t, 0.5;
    flip_toward_surface_delaunay(D, X, F, {margin_deg * degree});
    EXPECT_EQ(count_flipped(D, F), 0);
    return has_edge(F, 2, 3);
  };
  EXPECT_TRUE(joins_y_poles(190, 5));
  EXPECT_FALSE(joins_y_poles(190, 15));
  EXPECT_TRUE(joins_y_poles(200, 15));
}
