// The base-mesh domain (ParameterDomain::base_mesh): MAPS, the levels in the charts of K, and
// remesh() on it, on shapes whose one-chart maps onto the sphere are extreme.
#include <gtest/gtest.h>

#include <string>

#include "mesh/distance.h"
#include "mesh/primitives.h"
#include "mesh/quality.h"
#include "mesh/subdivision.h"
#include "mesh/topology.h"
#include "remesh/base_levels.h"
#include "remesh/remesh.h"
#include "remesh/remesh_options_json.h"
#include "tests/remesh/remesh_shapes.h"

namespace mrsnake {
namespace {

RemeshOptions base_domain_options(int target_faces) {
  RemeshOptions o;
  o.domain = ParameterDomain::base_mesh;
  o.target_faces = target_faces;
  return o;
}

// Nested exactly, unflipped in D, on the input, and the right topology, at every level.
void expect_valid_hierarchy(const RemeshResult& r, const TriMesh& input) {
  const SubdivisionConnectivity& c = r.connectivity;
  const SubdivisionConnectivity again = subdivide_connectivity(c.faces[0], c.vertex_count(0), c.levels());
  const SurfaceLocator locator(input);
  const double diag = bounding_box_diagonal(input.V);
  ASSERT_EQ(static_cast<int>(r.levels.size()), c.levels() + 1);
  for (int j = 0; j <= c.levels(); ++j) {
    SCOPED_TRACE("level " + std::to_string(j));
    EXPECT_TRUE(c.faces[j] == again.faces[j]);
    EXPECT_EQ(r.levels[j].flipped_triangles, 0);
    EXPECT_EQ(r.levels[j].stats["flipped_triangles"].get<int>(), 0);
    EXPECT_TRUE(topology_report(r.mesh(j)).is_closed_genus0());
    // Lifted vertices lie on the input; the finest level's fit moves them by < 0.15 of an edge.
    const double off = locator.distances(r.levels[j].positions).maxCoeff();
    EXPECT_LT(off, j < c.levels() ? 1e-9 * diag : 0.05 * diag);
  }
}

TEST(BaseDomainRemesh, ALongCapsuleNestsUnflippedAndWellShaped) {
  // Length 20: a one-chart map onto the sphere squeezes its far end by over 12 orders of
  // magnitude; on the base mesh every part keeps a domain area in proportion to its own.
  const TriMesh input = test::capsule(20.0, 24);
  const RemeshResult r = remesh(input, base_domain_options(4000));
  EXPECT_EQ(r.domain, "base_mesh");
  expect_valid_hierarchy(r, input);
  const nlohmann::json q = mesh_quality(r.mesh(r.connectivity.levels()));
  EXPECT_GT(q["q_mean"].get<double>(), 0.85) << q.dump();
  EXPECT_GT(q["min_angle_deg"].get<double>(), 20.0) << q.dump();
}

TEST(BaseDomainRemesh, WithoutRelaxationTheLevelsAreTheMapsRemesh) {
  RemeshOptions o = base_domain_options(2000);
  o.relax = RelaxMode::none;
  const TriMesh input = test::ellipsoid(4);
  const RemeshResult r = remesh(input, o);
  expect_valid_hierarchy(r, input);
  // Level 0 is K: its vertices are input vertices.
  const SurfaceLocator locator(input);
  EXPECT_LT(locator.distances(r.levels[0].positions).maxCoeff(), 1e-12);
}

TEST(BaseLevels, FlipCountSeesReversedAndUnchartedTriangles) {
  const BaseDomain domain(icosphere(0));
  const auto point = [](int face, double a, double b) { return BasePoint{face, Eigen::Vector3d(a, b, 1 - a - b)}; };
  const std::vector<BasePoint> points = {point(0, 0.6, 0.2), point(0, 0.2, 0.6), point(0, 0.2, 0.2)};
  // The corners' order in face 0 is counter-clockwise: (0.6, 0.2, 0.2) -> (0.2, 0.6, 0.2) -> (0.2, 0.2, 0.6).
  RowMatrixX3i F(1, 3);
  F << 0, 1, 2;
  EXPECT_EQ(count_flipped_on_base(domain, F, points), 0);
  F << 0, 2, 1;
  EXPECT_EQ(count_flipped_on_base(domain, F, points), 1);
  // A face of K that shares no vertex with face 0: no chart holds the triangle.
  const RowMatrixX3i& K = domain.base().F;
  int far_face = -1;
  for (int f = 0; f < K.rows() && far_face < 0; ++f) {
    bool shares = false;
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) shares = shares || K(f, a) == K(0, b);
    if (!shares) far_face = f;
  }
  ASSERT_GE(far_face, 0);
  std::vector<BasePoint> apart = points;
  apart[2] = point(far_face, 0.3, 0.3);
  F << 0, 1, 2;
  EXPECT_EQ(count_flipped_on_base(domain, F, apart), 1);
}

TEST(BaseDomainRemesh, OptionNameRoundTripsThroughJson) {
  RemeshOptions o = base_domain_options(1000);
  const nlohmann::json j = o;
  EXPECT_EQ(j["domain"], "base_mesh");
  EXPECT_EQ(j.get<RemeshOptions>().domain, ParameterDomain::base_mesh);
}

}  // namespace
}  // namespace mrsnake
