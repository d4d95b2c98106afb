// Tests of the remesher (section 4 of the seed paper).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "mesh/quality.h"
#include "mesh/topology.h"
#include "remesh/base_mesh.h"
#include "remesh/domain.h"
#include "remesh/lift.h"
#include "remesh/lloyd.h"
#include "remesh/parameterization.h"
#include "remesh/remesh.h"
#include "remesh/simplify.h"
#include "remesh/sizing.h"
#include "remesh/triangle_repair.h"
#include "tests/remesh/remesh_shapes.h"
#include "tests/test_support.h"

namespace mrsnake {
namespace {

using test::ellipsoid;
using test::spherical_cap;

std::set<std::pair<int, int>> edges_of(const RowMatrixX3i& F) {
  std::set<std::pair<int, int>> e;
  for (int f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = F(f, k), b = F(f, (k + 1) % 3);
      e.insert({std::min(a, b), std::max(a, b)});
    }
  return e;
}

RemeshOptions small_options(int levels, int base_vertices, RelaxMode mode = RelaxMode::all_vertices) {
  RemeshOptions o;
  o.levels = levels;
  o.base_vertices = base_vertices;
  o.relax = mode;
  o.compute_stats = false;
  return o;
}

void expect_nested_and_valid(const RemeshResult& r, const TriMesh& input, bool closed) {
  const auto& conn = r.connectivity;
  const int L = conn.levels();
  ASSERT_EQ(static_cast<int>(r.levels.size()), L + 1);
  const int n0 = conn.vertex_count(0);
  // The connectivity is exactly that of subdivide_connectivity of level 0.
  const SubdivisionConnectivity again = subdivide_connectivity(conn.faces[0], n0, L);
  const double diag = bounding_box_diagonal(input.V);
  const SurfaceLocator locator(input);
  for (int j = 0; j <= L; ++j) {
    SCOPED_TRACE("level " + std::to_string(j));
    EXPECT_TRUE(conn.faces[j] == again.faces[j]);
    EXPECT_EQ(conn.vertex_count(j), again.vertex_count(j));
    ASSERT_EQ(r.levels[j].positions.rows(), conn.vertex_count(j));
    ASSERT_EQ(r.levels[j].domain_positions.rows(), conn.vertex_count(j));
    EXPECT_EQ(r.levels[j].flipped_triangles, 0);
    EXPECT_EQ(count_flipped(r.levels[j].domain_positions, conn.faces[j]), 0);
    if (j > 0) {
      // Exact counts: F_j = 4 F_{j-1}, n_j = n_{j-1} + E_{j-1}.
      EXPECT_EQ(conn.faces[j].rows(), 4 * conn.faces[j - 1].rows());
      const auto previous_edges = edges_of(conn.faces[j - 1]);
      EXPECT_EQ(conn.vertex_count(j), conn.vertex_count(j - 1) + static_cast<int>(previous_edges.size()));
      if (closed) {
        EXPECT_EQ(2 * static_cast<int>(previous_edges.size()), 3 * static_cast<int>(conn.faces[j - 1].rows()));
      }
      // Every new vertex records an edge of the previous level as its parent.
      for (int v = conn.vertex_count(j - 1); v < conn.vertex_count(j); ++v) {
        const Eigen::Vector2i p = conn.parents(v);
        EXPECT_TRUE(previous_edges.count({std::min(p[0], p[1]), std::max(p[0], p[1])})) << "vertex " << v;
        EXPECT_EQ(conn.level_of_vertex(v), j);
      }
    }
    // Lifted vertices lie on the input surface; the finest level's fit moves them off it along
    // their normals, by at most 0.15 x their mean edge length (SurfaceFitOptions::max_offset).
    // These shapes do not cross themselves, so the untangling moves nothing.
    ASSERT_FALSE(r.levels[j].stats.contains("untangle")) << j;
    const double off_surface = locator.distances(r.levels[j].positions).maxCoeff();
    if (j < L || !r.levels[j].stats.contains("fit")) {
      EXPECT_LT(off_surface, 1e-9 * diag);
    } else {
      double longest_edge = 0;
      const RowMatrixX3i& F = conn.faces[j];
      for (int f = 0; f < F.rows(); ++f)
        for (int k = 0; k < 3; ++k)
          longest_edge = std::max(
              longest_edge, (r.levels[j].positions.row(F(f, k)) - r.levels[j].positions.row(F(f, (k + 1) % 3))).norm());
      EXPECT_LE(off_surface, 0.15 * longest_edge + 1e-9 * diag);
      EXPECT_GT(off_surface, 0.0);  // the fit ran
    }
    const TopologyReport topo = topology_report(r.mesh(j));
    EXPECT_TRUE(closed ? topo.is_closed_genus0() : topo.is_disk()) << topo.describe();
  }
}

TEST(Remesh, EllipsoidNestsExactlyWithoutFlipsInEveryModeAndSphereMap) {
  const TriMesh input = ellipsoid(4);
  for (SphereMap map : {SphereMap::punctured, SphereMap::two_halves}) {
    for (RelaxMode mode : {RelaxMode::all_vertices, RelaxMode::new_vertices_only, RelaxMode::none}) {
      SCOPED_TRACE(std::string(map == SphereMap::two_halves ? "two halves" : "punctured") + ", relax mode " +
                   std::to_string(static_cast<int>(mode)));
      RemeshOptions options = small_options(3, 20, mode);
      options.sphere_map = map;
      const RemeshResult r = remesh(input, options);
      EXPECT_EQ(r.parameterization.contains("cut_vertices"), map == SphereMap::two_halves);
      EXPECT_EQ(r.domain, "sphere");
      EXPECT_EQ(r.connectivity.vertex_count(0), 20);
      EXPECT_EQ(r.connectivity.faces[0].rows(), 36);  // closed: F0 = 2 n0 - 4
      EXPECT_EQ(r.connectivity.faces[3].rows(), 36 * 64);
      EXPECT_EQ(r.connectivity.vertex_count(3), 2 + 36 * 64 / 2);
      expect_nested_and_valid(r, input, true);
    }
  }
}

// A needle eight input edges long on a sphere is far thinner than the edges of a 3840-face
// level: the level cuts it off, and the report says so, with the distance in edges. The same
// sphere without the needle is not suspect.
TEST(Remesh, AFinestLevelThatCutsANeedleOffIsSuspect) {
  TriMesh needle = icosphere(4);  // 5120 faces, edges of about 0.075
  needle.V.row(0) *= 1.6;
  const auto finest_doubts = [](const TriMesh& input) {
    RemeshOptions o = small_options(3, 32);
    o.compute_stats = true;
    const RemeshResult r = remesh(input, o);
    const std::vector<std::string> doubts = finest_level_doubts(r).value();
    const nlohmann::json report = remesh_report(r, o);
    EXPECT_EQ(report["suspect"].get<bool>(), !doubts.empty());
    EXPECT_EQ(report["suspect_reasons"].get<std::vector<std::string>>(), doubts);
    const nlohmann::json& finest = r.levels.back().stats;
    const double hausdorff_in_edges =
        finest["distance"]["hausdorff_mm"].get<double>() / finest["quality"]["edge_length_mean"].get<double>();
    return std::make_pair(doubts, hausdorff_in_edges);
  };
  const auto [cut, cut_edges] = finest_doubts(needle);
  EXPECT_GT(cut_edges, 2.0);
  ASSERT_EQ(cut.size(), 1u);
  EXPECT_NE(cut[0].find("misses part of the input by"), std::string::npos) << cut[0];
  const auto [kept, kept_edges] = finest_doubts(icosphere(4));
  EXPECT_LT(kept_edges, 0.5);
  EXPECT_TRUE(kept.empty());
  // Unmeasured levels are not judged: no verdict, rather than a "not suspect" that nothing backs.
  RemeshOptions unmeasured = small_options(3, 32);
  const RemeshResult r = remesh(needle, unmeasured);
  EXPECT_FALSE(finest_level_doubts(r).has_value());
  EXPECT_FALSE(remesh_report(r, unmeasured).contains("suspect"));
}

TEST(Remesh, FineInputIsSimplifiedThenProjectedBackOntoIt) {
  const TriMesh input = ellipsoid(5);  // 20480 faces
  RemeshOptions o = small_options(2, 20);
  o.simplify.above_faces = 2000;
  const RemeshResult r = remesh(input, o);
  EXPECT_LT(r.parameterization["parameterized_faces"].get<int>(), input.num_faces());
  EXPECT_GE(r.parameterization["parameterized_faces"].get<int>(), 2000);
  expect_nested_and_valid(r, input, true);  // includes: every vertex lies on the original input (the finest near it)
}

TEST(Remesh, AnInputOfLargeSliversIsRemeshedIsotropicallyThenProjectedBackOntoIt) {
  // The tube's 160 triangles of 384 are 4 long and 0.39 wide (Q 0.16), as decimation leaves a
  // limb: the lift, affine on each, shears the level's triangles over them.
  const TriMesh input = test::capsule(20.0, 16, 4.0);
  RemeshOptions o;
  o.target_faces = 4000;
  o.domain = ParameterDomain::sphere;  // the base-mesh domain would split the kept input's faces
  const RemeshResult remeshed = remesh(input, o);
  ASSERT_TRUE(remeshed.parameterization.contains("sliver_share")) << remeshed.parameterization.dump();
  EXPECT_NEAR(remeshed.parameterization.at("sliver_share").get<double>(), 160.0 / 384.0, 1e-12);
  EXPECT_TRUE(remeshed.parameterization.at("sliver_remeshed").get<bool>());
  EXPECT_GT(remeshed.parameterization.at("parameterized_faces").get<int>(), 4 * input.num_faces());
  expect_nested_and_valid(remeshed, input, true);  // includes: every vertex lies on the original input
  o.simplify.sliver_share = 1.0;
  const RemeshResult kept = remesh(input, o);
  EXPECT_FALSE(kept.parameterization.contains("sliver_share"));
  EXPECT_EQ(kept.parameterization.at("parameterized_faces").get<int>(), input.num_faces());
  // What the isotropic input buys: rounder triangles at the finest level.
  const double q_remeshed = remeshed.levels.back().stats["quality"]["q_mean"].get<double>();
  const double q_kept = kept.levels.back().stats["quality"]["q_mean"].get<double>();
  EXPECT_GT(q_remeshed, 0.9);
  EXPECT_LT(q_kept, 0.6);
}

// Edges of (V, F) shorter than `length`, each counted once.
int edges_shorter_than(const TriMesh& mesh, double length) {
  int count = 0;
  for (int f = 0; f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      if (a < b && (mesh.V.row(a) - mesh.V.row(b)).norm() < length) ++count;
    }
  return count;
}

TEST(Simplification, HalvesStitchIntoOneClosedSurfaceOfTheWantedSize) {
  // Two cores each simplify one half, the faces at the cut frozen; the stitched halves must be one closed
  // genus-0 surface (a cut vertex kept twice would open a boundary), of the wanted size, near
  // the input, and the cut (still at the input's resolution when stitched) collapsed like the rest.
  const TriMesh input = ellipsoid(5);  // 20480 faces, mean edge 0.074
  const double input_mean_edge = mesh_quality(input).edge_length_mean;
  const TriMesh out = detail::simplify_in_two_halves(input, 3000);
  const TopologyReport t = topology_report(out);
  EXPECT_TRUE(t.is_closed_genus0());
  EXPECT_TRUE(t.is_manifold());
  EXPECT_EQ(t.degenerate_faces, 0);
  EXPECT_GE(out.num_faces(), 2990);
  EXPECT_LE(out.num_faces(), 3000);
  const SurfaceLocator near_input(input);
  EXPECT_LT(near_input.distances(out.V).maxCoeff(), 0.05);
  EXPECT_LT(edges_shorter_than(out, input_mean_edge), 15) << "of " << out.num_faces() * 3 / 2 << " edges";

  const TriMesh cap = spherical_cap(5);  // a disk stays a disk
  const TriMesh cap_out = detail::simplify_in_two_halves(cap, 1500);
  EXPECT_TRUE(topology_report(cap_out).is_disk());
  EXPECT_NEAR(cap_out.num_faces(), 1500, 30);
  // The public entry gives the same surface.
  const TriMesh again = simplify_to_faces(input, 3000);
  ASSERT_EQ(again.num_vertices(), out.num_vertices());
  ASSERT_EQ(again.num_faces(), out.num_faces());
  EXPECT_TRUE(again.V == out.V && again.F == out.F);
}

TEST(Remesh, StrictModeKeepsCoarseVerticesInTheDomain) {
  const RemeshResult r = remesh(ellipsoid(3), small_options(2, 16, RelaxMode::new_vertices_only));
  for (int j = 1; j <= 2; ++j) {
    const int n = r.connectivity.vertex_count(j - 1);
    EXPECT_TRUE(r.levels[j].domain_positions.topRows(n).isApprox(r.levels[j - 1].domain_positions, 1e-15));
  }
}

TEST(Remesh, DiskInputStaysADiskWithBoundaryOnTheCircle) {
  const TriMesh input = spherical_cap(4);
  ASSERT_TRUE(topology_report(input).is_disk());
  const RemeshResult r = remesh(input, small_options(3, 24));
  EXPECT_EQ(r.domain, "disk");
  expect_nested_and_valid(r, input, false);
  const RowMatrixX3d& D = r.levels.back().domain_positions;
  const auto boundary = boundary_vertices(r.connectivity.faces.back(), static_cast<int>(D.rows()));
  for (int v = 0; v < D.rows(); ++v) {
    EXPECT_DOUBLE_EQ(D(v, 2), 1.0);
    if (boundary[v])
      EXPECT_NEAR(std::hypot(D(v, 0), D(v, 1)), 1.0, 1e-12);
    else
      EXPECT_LT(std::hypot(D(v, 0), D(v, 1)), 1.0);
  }
}

TEST(Remesh, TargetFacesChoosesBaseAndLevels) {
  RemeshOptions o;
  o.target_faces = 4000;
  o.compute_stats = false;
  const RemeshResult r = remesh(ellipsoid(4), o);
  const double finest = static_cast<double>(r.connectivity.faces.back().rows());
  EXPECT_GT(finest, 4000 / 1.3);
  EXPECT_LT(finest, 4000 * 1.3);
  EXPECT_GE(r.connectivity.vertex_count(0), 60);
  EXPECT_LE(r.connectivity.vertex_count(0), 300);
}

TEST(Remesh, RelaxedBeatsUnrelaxedOnAnEllipsoid) {
  const TriMesh input = ellipsoid(4);
  RemeshOptions relaxed = small_options(3, 24);
  relaxed.compute_stats = true;
  RemeshOptions plain = relaxed;
  plain.relax = RelaxMode::none;
  const auto a = remesh(input, relaxed).levels.back().stats;
  const auto b = remesh(input, plain).levels.back().stats;
  const auto& qa = a["quality"];
  const auto& qb = b["quality"];
  EXPECT_GT(qa["min_angle_deg"].get<double>(), qb["min_angle_deg"].get<double>());
  EXPECT_GT(qa["q_min"].get<double>(), qb["q_min"].get<double>());
  EXPECT_GT(qa["q_mean"].get<double>(), qb["q_mean"].get<double>());
  EXPECT_LT(qa["edge_length_cv"].get<double>(), qb["edge_length_cv"].get<double>());
  EXPECT_LT(qa["area_cv"].get<double>(), qb["area_cv"].get<double>());
  EXPECT_LE(a["distance"]["hausdorff_pct"].get<double>(), b["distance"]["hausdorff_pct"].get<double>());
}

TEST(Remesh, RefusesOtherTopologiesNamingWhatWasFound) {
  TriMesh two = icosphere(1);
  TriMesh shifted = icosphere(1);
  shifted.V.col(0).array() += 5.0;
  TriMesh both;
  both.V.resize(two.V.rows() * 2, 3);
  both.V << two.V, shifted.V;
  both.F.resize(two.F.rows() * 2, 3);
  both.F << two.F, (shifted.F.array() + static_cast<int>(two.V.rows())).matrix();
  try {
    remesh(both, small_options(1, 8));
    FAIL() << "two components were accepted";
  } catch (const TopologyError& e) {
    EXPECT_NE(std::string(e.what()).find("component"), std::string::npos) << e.what();
  }
}

TEST(Remesh, ParameterizationOfTheSphereIsBalancedAndUnflipped) {
  const TriMesh input = ellipsoid(3);
  const Parameterization p = parameterize(input);
  EXPECT_EQ(p.kind, DomainKind::sphere);
  EXPECT_EQ(count_flipped(p.domain, p.surface.F), 0);
  for (int v = 0; v < p.domain.rows(); ++v) EXPECT_NEAR(p.domain.row(v).norm(), 1.0, 1e-12);
  EXPECT_TRUE((p.face_stretch.array() > 0).all());
}

TEST(Remesh, MobiusMapKeepsTheSphereAndCentresThePoint) {
  const Eigen::Vector3d a(0.3, -0.2, 0.5);
  const TriMesh s = icosphere(2);
  for (int v = 0; v < s.num_vertices(); ++v)
    EXPECT_NEAR(mobius_to_center(a, s.V.row(v).transpose()).norm(), 1.0, 1e-12);
  // Orientation is preserved.
  for (int f = 0; f < s.num_faces(); ++f) {
    const Eigen::Vector3d p = mobius_to_center(a, s.V.row(s.F(f, 0))), q = mobius_to_center(a, s.V.row(s.F(f, 1))),
                          r = mobius_to_center(a, s.V.row(s.F(f, 2)));
    EXPECT_GT(domain_orientation(p, q, r), 0);
  }
}

TEST(Sizing, CurvatureOfASphereIsOneOverItsRadius) {
  const TriMesh sphere = icosphere(4, 2.0);
  const Eigen::VectorXd kappa = vertex_curvature(sphere);
  EXPECT_NEAR(kappa.minCoeff(), 0.5, 0.03);
  EXPECT_NEAR(kappa.maxCoeff(), 0.5, 0.03);
  // A flatter ellipsoid bends most at the ends of its long axis.
  const TriMesh e = ellipsoid(4);
  const Eigen::VectorXd k = vertex_curvature(e);
  int tip = 0, side = 0;
  e.V.col(0).maxCoeff(&tip);
  e.V.col(2).maxCoeff(&side);
  EXPECT_GT(k[tip], 2 * k[side]);
}

// The paper's Fig. 1: a vertex with a non-convex 1-ring. Its Voronoi cell pokes out of the
// ring (an obtuse triangle's circumcenter lies outside), while N(v) stays inside, and the
// constrained Lloyd iteration flips nothing.
TEST(Lloyd, CellStaysInsideANonConvexOneRing) {
  RowMatrixX3d U(7, 3);
  U << 0, 0, 1,       // v
      1.0, 0.0, 1,    //
      0.5, 0.05, 1,   // reflex ring vertex, close to v: non-convex ring
      0.0, 1.0, 1,    //
      -1.0, 0.2, 1,   //
      -0.6, -1.0, 1,  //
      0.6, -1.0, 1;
  RowMatrixX3i F(6, 3);
  F << 0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 4, 5, 0, 5, 6, 0, 6, 1;
  ASSERT_EQ(count_flipped(U, F), 0);
  auto inside_ring = [&](const Eigen::Vector3d& p) {
    // Inside the 1-ring = inside one of its triangles (closed).
    for (int f = 0; f < F.rows(); ++f) {
      const Eigen::Vector3d a = U.row(F(f, 0)), b = U.row(F(f, 1)), c = U.row(F(f, 2));
      if (domain_orientation(p, b, c) >= -1e-12 && domain_orientation(a, p, c) >= -1e-12 &&
          domain_orientation(a, b, p) >= -1e-12)
        return true;
    }
    return false;
  };
  // The ring is non-convex at vertex 2 ...
  EXPECT_LT(domain_orientation(U.row(1), U.row(2), U.row(3)), 0);
  // ... and the circumcenter of the obtuse triangle (v, 1, 2) lies outside the ring.
  const Eigen::Vector2d a(0, 0), b(1, 0), c(0.5, 0.05);
  const double d = 2 * (a.x() * (b.y() - c.y()) + b.x() * (c.y() - a.y()) + c.x() * (a.y() - b.y()));
  const Eigen::Vector3d circumcenter(
      (a.squaredNorm() * (b.y() - c.y()) + b.squaredNorm() * (c.y() - a.y()) + c.squaredNorm() * (a.y() - b.y())) / d,
      (a.squaredNorm() * (c.x() - b.x()) + b.squaredNorm() * (a.x() - c.x()) + c.squaredNorm() * (b.x() - a.x())) / d,
      1);
  EXPECT_FALSE(inside_ring(circumcenter));
  const auto cell = lloyd_cell(F, U, 0);
  ASSERT_EQ(cell.size(), 6u);
  double cell_area = 0, ring_area = 0;
  for (const auto& quad : cell) {
    for (const auto& p : quad) EXPECT_TRUE(inside_ring(p)) << p.transpose();
    cell_area += 0.5 * ((quad[1] - quad[0]).cross(quad[2] - quad[0]).norm() +
                        (quad[2] - quad[0]).cross(quad[3] - quad[0]).norm());
  }
  for (int f = 0; f < F.rows(); ++f)
    ring_area += 0.5 * (U.row(F(f, 1)) - U.row(F(f, 0))).cross(U.row(F(f, 2)) - U.row(F(f, 0))).norm();
  EXPECT_NEAR(cell_area, ring_area / 3, 1e-12);  // N(v) is a third of each 1-ring triangle
  EXPECT_TRUE(inside_ring(lloyd_cell_centroid(F, U, 0)));

  // Relax v under a constant density on a domain mesh covering the ring.
  std::vector<int> hints(7, 0);
  LloydOptions options;
  options.iterations = 50;
  // Only v moves (the ring vertices are "coarse"): make v the last vertex.
  RowMatrixX3d W(7, 3);
  W << U.bottomRows(6), U.row(0);
  RowMatrixX3i G = F;
  for (int f = 0; f < G.rows(); ++f)
    for (int k = 0; k < 3; ++k) G(f, k) = G(f, k) == 0 ? 6 : G(f, k) - 1;
  options.first_movable = 6;
  const DomainMesh wdomain(W, G);
  DensityField wdensity{&wdomain, Eigen::VectorXd::Ones(7)};
  const LloydStats stats = constrained_lloyd(DomainKind::disk, G, wdensity, W, hints, options);
  EXPECT_EQ(count_flipped(W, G), 0);
  EXPECT_GT(stats.moves, 0);
  // Converged to its own cell's centroid.
  EXPECT_LT((lloyd_cell_centroid(G, W, 6) - Eigen::Vector3d(W.row(6))).norm(), 1e-6);
}

// Under a density linear on D, one step at a fine level's sampling (one density sample per
// quadrilateral) takes v exactly to the centroid of its cell weighted by each quadrilateral's
// density at its own centroid.
TEST(Lloyd, LinearDensityMovesTheVertexToItsWeightedCentroid) {
  RowMatrixX3d U(7, 3);
  U << 0.6, -1.0, 1, 1.0, 0.0, 1, 0.5, 0.05, 1, 0.0, 1.0, 1, -1.0, 0.2, 1, -0.6, -1.0, 1, 0.1, -0.1, 1;
  RowMatrixX3i F(6, 3);  // vertex 6 and its ring 0..5
  F << 6, 1, 2, 6, 2, 3, 6, 3, 4, 6, 4, 5, 6, 5, 0, 6, 0, 1;
  ASSERT_EQ(count_flipped(U, F), 0);
  const auto rho = [](const Eigen::Vector3d& p) { return 2.0 + 0.8 * p.x() - 0.5 * p.y(); };
  Eigen::VectorXd vertex_density(7);
  for (int v = 0; v < 7; ++v) vertex_density[v] = rho(U.row(v).transpose());
  Eigen::Vector3d moment = Eigen::Vector3d::Zero();
  double mass = 0;
  for (int f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d p = U.row(6), a = U.row(F(f, 1)), b = U.row(F(f, 2));
    const Eigen::Vector3d quad_centroid = (11.0 / 18.0) * p + (7.0 / 36.0) * (a + b);
    const double weight = rho(quad_centroid) * (a - p).cross(b - p).norm() / 6.0;
    mass += weight;
    moment += weight * quad_centroid;
  }
  RowMatrixX3d W = U;
  const DomainMesh domain(U, F);
  const DensityField density{&domain, vertex_density};
  std::vector<int> hints(7, 0);
  LloydOptions options;
  options.iterations = 1;
  options.first_movable = 6;
  options.sample_budget = 6;  // one sample per corner quadrilateral, as on a fine level
  constrained_lloyd(DomainKind::disk, F, density, W, hints, options);
  EXPECT_LT((Eigen::Vector3d(W.row(6)) - moment / mass).norm(), 1e-12);
  EXPECT_GT((W.row(6) - U.row(6)).norm(), 0.01);  // it did move
}

// The final repair: on an ellipsoid's parameterization, a triangulation of D with a few
// vertices pushed toward a neighbour (sliver triangles in 3D) is repaired in place: the
// smallest Q goes up a lot, nothing flips in D, and every vertex is still the exact lift of
// its domain position (so on the surface).
TEST(TriangleRepair, RaisesTheWorstQualityOnTheSurfaceWithoutFlips) {
  const TriMesh input = ellipsoid(4);
  const Parameterization param = parameterize(input);
  const DomainMesh domain(param.domain, param.surface.F);
  TriMesh grid = icosphere(3);
  const RowMatrixX3i& F = grid.F;
  RowMatrixX3d U = test::sheared_layout(grid.V.rowwise().normalized(), F);
  ASSERT_EQ(count_flipped(U, F), 0);
  std::vector<int> hints(U.rows(), 0);
  RowMatrixX3d X = lift_to_surface(domain, param.surface.V, U, hints);
  const double q_before = mesh_quality(TriMesh{X, F}).q_min;
  ASSERT_LT(q_before, 0.3);
  const TriangleRepairStats stats =
      repair_worst_triangles(DomainKind::sphere, F, domain, param.surface.V, U, X, hints, TriangleRepairOptions{});
  const double q_after = mesh_quality(TriMesh{X, F}).q_min;
  EXPECT_GT(stats.moves, 0);
  EXPECT_NEAR(stats.q_min_before, q_before, 1e-12);
  EXPECT_NEAR(stats.q_min_after, q_after, 1e-12);
  EXPECT_GT(q_after, 0.5);
  EXPECT_EQ(count_flipped(U, F), 0);
  for (int v = 0; v < U.rows(); ++v) EXPECT_NEAR(U.row(v).norm(), 1.0, 1e-12);
  std::vector<int> fresh(U.rows(), 0);
  EXPECT_LT((lift_to_surface(domain, param.surface.V, U, fresh) - X).cwiseAbs().maxCoeff(), 1e-9);
  const SurfaceLocator locator(input);
  EXPECT_LT(locator.distances(X).maxCoeff(), 1e-9 * bounding_box_diagonal(input.V));
}

// With the surface-error guard (and no tolerance) no edge leaves the surface further than
// before: the largest distance between an edge's 3D midpoint and the lift of its midpoint in
// D cannot grow, since a move only changes the moved vertex's edges and must keep them within
// the old largest. The guard does refuse moves that the unguarded repair makes.
TEST(TriangleRepair, GuardKeepsEdgesAsCloseToTheSurface) {
  const TriMesh input = ellipsoid(4);
  const Parameterization param = parameterize(input);
  const DomainMesh domain(param.domain, param.surface.F);
  const TriMesh grid = icosphere(3);
  RowMatrixX3d U0 = grid.V.rowwise().normalized();
  const RowMatrixX3i& F = grid.F;
  {
    // Slivers at the most curved places (the ends of the long axis), where moves cut most.
    std::vector<int> hints(U0.rows(), 0);
    const RowMatrixX3d X0 = lift_to_surface(domain, param.surface.V, U0, hints);
    for (int f = 0; f < F.rows(); ++f) {
      const int v = F(f, 0), w = F(f, 1);
      if (std::abs(X0(v, 0)) < 2.0) continue;
      const Eigen::RowVector3d before = U0.row(v);
      U0.row(v) = (0.5 * U0.row(v) + 0.5 * U0.row(w)).normalized();
      if (count_flipped(U0, F) > 0) U0.row(v) = before;
    }
  }
  auto largest_edge_error = [&](const RowMatrixX3d& U, const RowMatrixX3d& X) {
    double error = 0;
    int hint = 0;
    for (const auto& [a, b] : edges_of(F)) {
      const Eigen::Vector3d mid = (U.row(a) + U.row(b)).normalized().transpose();
      const DomainMesh::Location loc = domain.locate(mid, hint);
      hint = loc.face;
      Eigen::Vector3d lifted = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k)
        lifted += loc.barycentric[k] * param.surface.V.row(domain.faces()(loc.face, k)).transpose();
      error = std::max(error, (lifted - 0.5 * (X.row(a) + X.row(b)).transpose()).norm());
    }
    return error;
  };
  std::vector<double> after(2);
  std::vector<int> moves(2);
  double before = 0;
  for (bool guard : {true, false}) {
    RowMatrixX3d U = U0;
    std::vector<int> hints(U.rows(), 0);
    RowMatrixX3d X = lift_to_surface(domain, param.surface.V, U, hints);
    before = largest_edge_error(U, X);
    TriangleRepairOptions options;
    options.guard_surface_error = guard;
    options.error_tolerance = 0;
    const TriangleRepairStats stats =
        repair_worst_triangles(DomainKind::sphere, F, domain, param.surface.V, U, X, hints, options);
    EXPECT_GT(stats.moves, 0);
    EXPECT_GT(stats.q_min_after, stats.q_min_before);
    after[guard ? 0 : 1] = largest_edge_error(U, X);
    moves[guard ? 0 : 1] = stats.moves;
  }
  EXPECT_LE(after[0], before * (1 + 1e-9));
  EXPECT_LT(moves[0], moves[1]);
}

// With repair on, every level's smallest Q is at least what it was before that level's repair
// (on a disk, rim vertices slide along the circle and stay on it; on a sphere), every level
// meets the angle targets, and the finest level beats the same run with repair off.
TEST(TriangleRepair, RaisesEveryLevelsWorstTriangleAndKeepsTheRimOnTheCircle) {
  for (const TriMesh& input : {spherical_cap(4), ellipsoid(4)}) {
    RemeshOptions on = small_options(3, 24);
    on.compute_stats = true;
    on.fit.rounds = 0;  // the level's Q is then the repair's own (the fit moves the finest level)
    RemeshOptions off = on;
    off.repair.sweeps = 0;
    const RemeshResult a = remesh(input, on), b = remesh(input, off);
    expect_nested_and_valid(a, input, a.domain == "sphere");
    int moves = 0;
    for (int j = 0; j <= 3; ++j) {
      SCOPED_TRACE("level " + std::to_string(j));
      const auto& s = a.levels[j].stats;
      moves += s["repair_moves"].get<int>();
      EXPECT_EQ(b.levels[j].stats["repair_moves"].get<int>(), 0);
      if (s["repair_moves"].get<int>() > 0) {
        EXPECT_GT(s["repair_q_min_after"].get<double>(), s["repair_q_min_before"].get<double>());
        EXPECT_NEAR(s["repair_q_min_after"].get<double>(), s["quality"]["q_min"].get<double>(), 1e-12);
      }
      EXPECT_GE(s["quality"]["q_min"].get<double>(), 0.6);
      EXPECT_GE(s["quality"]["min_angle_deg"].get<double>(), 30.0);
    }
    EXPECT_GT(moves, 0);
    EXPECT_GT(a.levels[3].stats["quality"]["q_min"].get<double>(), b.levels[3].stats["quality"]["q_min"].get<double>());
  }
}

// Rim vertices of a disk's base mesh with only 2 triangles are dropped: on the mushroom the
// old rule leaves some (their corners are ~120 degrees at every level), the new none.
TEST(RemeshData, MushroomBaseRimVerticesHaveThreeTriangles) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/mushroom.off");
  const Parameterization param = parameterize(read_mesh(path));
  auto thin_rim_vertices = [](const BaseMesh& base) {
    const int m = static_cast<int>(base.domain.rows());
    std::vector<int> triangles(m, 0);
    for (int f = 0; f < base.faces.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++triangles[base.faces(f, k)];
    const std::vector<bool> rim = boundary_vertices(base.faces, m);
    int thin = 0;
    for (int v = 0; v < m; ++v) thin += rim[v] && triangles[v] < 3;
    return thin;
  };
  int old_thin = 0;
  for (int n0 : {66, 127, 252}) {
    SCOPED_TRACE(n0);
    old_thin += thin_rim_vertices(build_base_mesh(param, n0, 1));
    const BaseMesh base = build_base_mesh(param, n0, 3);
    EXPECT_EQ(thin_rim_vertices(base), 0);
    EXPECT_EQ(count_flipped(base.domain, base.faces), 0);
    EXPECT_GT(base.domain.rows(), n0 * 9 / 10);
    EXPECT_EQ(static_cast<int>(base.domain.rows()) + base.dropped_rim_samples, n0);
  }
  EXPECT_GT(old_thin, 0);
}

// Real meshes: zero flipped triangles at every level (kept small for a fast suite).
void expect_no_flips_on(const std::string& path) {
  const TriMesh input = read_mesh(path);
  for (SphereMap map : {SphereMap::punctured, SphereMap::two_halves}) {
    for (RelaxMode mode : {RelaxMode::all_vertices, RelaxMode::new_vertices_only, RelaxMode::none}) {
      RemeshOptions o;
      o.target_faces = 4000;
      o.relax = mode;
      o.sphere_map = map;
      o.compute_stats = false;
      const RemeshResult r = remesh(input, o);
      if (r.domain == "sphere") {
        EXPECT_EQ(r.parameterization.contains("cut_vertices"), map == SphereMap::two_halves) << path;
      }
      for (int j = 0; j <= r.connectivity.levels(); ++j) {
        EXPECT_EQ(count_flipped(r.levels[j].domain_positions, r.connectivity.faces[j]), 0) << path << " level " << j;
        EXPECT_EQ(r.levels[j].flipped_triangles, 0);
      }
    }
  }
}

TEST(RemeshData, BlobbyHasNoFlippedTriangles) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/blobby.off");
  expect_no_flips_on(path);
}

TEST(RemeshData, MushroomHasNoFlippedTriangles) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/mushroom.off");
  expect_no_flips_on(path);
}

TEST(RemeshData, RetinalHasNoFlippedTriangles) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/retinal.off");
  expect_no_flips_on(path);
}

// The command line.
TEST(RemeshCli, WritesNestedLevelsAndReport) {
  const auto dir = test::scratch_dir("remesh-cli");
  const std::string input = (dir / "ellipsoid.off").string();
  write_mesh(input, ellipsoid(3));
  const auto out = dir / "model";
  const auto r = test::run_mrsnake("-q remesh " + input + " -o " + out.string() + " --levels 2 --base-vertices 12");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const TriMesh l0 = read_mesh((out / "level_0.vtp").string());
  const SubdivisionConnectivity conn = subdivide_connectivity(l0.F, l0.num_vertices(), 2);
  for (int j = 0; j <= 2; ++j) {
    const TriMesh lj = read_mesh((out / ("level_" + std::to_string(j) + ".vtp")).string());
    EXPECT_EQ(lj.num_vertices(), conn.vertex_count(j));
    EXPECT_TRUE(lj.F == conn.faces[j]) << "level " << j;
  }
  std::ifstream in(out / "report.json");
  const auto report = nlohmann::json::parse(in);
  ASSERT_EQ(report["per_level"].size(), 3u);
  for (const auto& level : report["per_level"]) {
    for (const char* key :
         {"vertices", "faces", "flipped_triangles", "self_intersections", "seconds", "quality", "distance"})
      EXPECT_TRUE(level.contains(key)) << key;
    // The stages' times are parts of the level's.
    ASSERT_TRUE(level.contains("stage_seconds"));
    double stages = 0;
    for (const auto& [stage, seconds] : level["stage_seconds"].items()) {
      EXPECT_GE(seconds.get<double>(), 0.0) << stage;
      stages += seconds.get<double>();
    }
    EXPECT_TRUE(level["stage_seconds"].contains("relax_in_domain"));
    EXPECT_LE(stages, level["seconds"].get<double>());
    EXPECT_EQ(level["self_intersections"].get<int>(), 0);
    EXPECT_TRUE(level["quality"].contains("q_min"));
    EXPECT_TRUE(level["quality"].contains("pct_valence6_interior"));
    EXPECT_TRUE(level["distance"].contains("rms_pct"));
    EXPECT_TRUE(level["distance"].contains("hausdorff_pct"));
    EXPECT_EQ(level["flipped_triangles"].get<int>(), 0);
  }
  EXPECT_EQ(r.output.find("passes through itself"), std::string::npos) << r.output;
  // A small input takes the punctured map by default; --sphere-map halves asks for the cut.
  EXPECT_FALSE(report["parameterization"].contains("cut_vertices"));
  const auto halves = test::run_mrsnake("-q remesh " + input + " -o " + (dir / "halves").string() +
                                        " --levels 2 --base-vertices 12 --sphere-map halves");
  ASSERT_EQ(halves.exit_code, 0) << halves.output;
  std::ifstream in_halves(dir / "halves" / "report.json");
  EXPECT_GT(nlohmann::json::parse(in_halves)["parameterization"].value("cut_vertices", 0), 0);
  EXPECT_EQ(test::run_mrsnake("-q remesh " + input + " -o " + (dir / "bad").string() + " --sphere-map north").exit_code,
            2);
  // The finest level is fitted by default (report key "fit"); --fit-rounds 0 turns it off.
  EXPECT_EQ(report["fit_rounds"].get<int>(), 1);
  EXPECT_TRUE(report["per_level"][2].contains("fit"));
  EXPECT_FALSE(report["per_level"][1].contains("fit"));
  const auto unfitted = test::run_mrsnake("-q remesh " + input + " -o " + (dir / "unfitted").string() +
                                          " --levels 2 --base-vertices 12 --fit-rounds 0");
  ASSERT_EQ(unfitted.exit_code, 0) << unfitted.output;
  std::ifstream in_unfitted(dir / "unfitted" / "report.json");
  const auto unfitted_report = nlohmann::json::parse(in_unfitted);
  EXPECT_FALSE(unfitted_report["per_level"][2].contains("fit"));
  EXPECT_LT(report["per_level"][2]["distance"]["rms_pct"].get<double>(),
            unfitted_report["per_level"][2]["distance"]["rms_pct"].get<double>());
  EXPECT_EQ(test::run_mrsnake("-q remesh " + input + " -o " + (dir / "bad").string() + " --fit-rounds -1").exit_code,
            2);
  std::filesystem::remove_all(dir);
}

// The octopus's tentacle tips are thinner than the edges of a 1000-face level: its triangles
// cross there, and the untangling opens only some of the folds. The count is recorded per
// level and the finest level's is a warning, as the quality figures alone would not show it;
// so is the tentacles' length that the level cuts off.
TEST(RemeshCli, FlagsAFinestLevelThatPassesThroughItselfOrCutsTipsOff) {
  MRSNAKE_REQUIRE_DATA(octopus, "meshes/octopus.off");
  const auto dir = test::scratch_dir("remesh-crossing");
  const auto r = test::run_mrsnake("-q remesh " + octopus + " -o " + dir.string() + " --faces 1000");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(dir / "report.json");
  const auto report = nlohmann::json::parse(in);
  const auto& levels = report["per_level"];
  for (std::size_t j = 0; j < levels.size(); ++j)
    EXPECT_EQ(levels[j]["self_intersections"].get<int>(),
              count_self_intersections(read_mesh((dir / ("level_" + std::to_string(j) + ".vtp")).string())))
        << j;
  const int finest = levels.back()["self_intersections"].get<int>();
  ASSERT_GT(finest, 0) << "the octopus no longer folds at 1000 faces: take a harder input";
  EXPECT_NE(
      r.output.find("warning: the finest level passes through itself at " + std::to_string(finest) + " face pairs"),
      std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("warning: the finest level misses part of the input by more than its mean edge length"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(report["suspect"].get<bool>());
  EXPECT_EQ(report["suspect_reasons"].size(), 2u);
  std::filesystem::remove_all(dir);
}

TEST(RemeshCli, RefusesGenus3AndFiveBoundaryLoopsWritingNothing) {
  const auto dir = test::scratch_dir("remesh-refuse");
  {
    MRSNAKE_REQUIRE_DATA(elephant, "meshes/elephant.off");
    const auto r = test::run_mrsnake("remesh " + elephant + " -o " + (dir / "e").string());
    EXPECT_EQ(r.exit_code, 3) << r.output;
    EXPECT_NE(r.output.find("genus 3"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "e"));
  }
  {
    MRSNAKE_REQUIRE_DATA(lion, "meshes/lion.off");
    const auto r = test::run_mrsnake("remesh " + lion + " -o " + (dir / "l").string());
    EXPECT_EQ(r.exit_code, 3) << r.output;
    EXPECT_NE(r.output.find("5 boundary loops"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "l"));
  }
  std::filesystem::remove_all(dir);
}

TEST(RemeshCli, DegenerateInputFailsWithoutWriting) {
  const auto dir = test::scratch_dir("remesh-degenerate");
  // Every triangle has zero area, so no parameterization exists: all vertices at one point, or
  // on one line (edges of nonzero length: every triangle a sliver of no area, which no
  // isotropic remeshing can make whole).
  TriMesh point = icosphere(2), line = icosphere(2);
  point.V.setZero();
  line.V.rightCols(2).setZero();
  for (const auto& [name, mesh] : {std::pair{"point", point}, std::pair{"line", line}}) {
    const std::string input = (dir / (std::string(name) + ".off")).string();
    write_mesh(input, mesh);
    const auto out = dir / (std::string(name) + "-out");
    const auto r = test::run_mrsnake("remesh " + input + " -o " + out.string() + " --levels 1");
    EXPECT_NE(r.exit_code, 0) << name << ": " << r.output;
    EXPECT_NE(r.exit_code, 1) << name << ": an internal error instead of a clear message: " << r.output;
    EXPECT_FALSE(std::filesystem::exists(out / "level_0.vtp")) << name;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mrsnake
