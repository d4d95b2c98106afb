// Tests of the base-mesh domain: the conformal star flattening, the charts of BaseDomain
// (round trips, points on shared edges, orientation, common charts) and the inverse map
// BaseLift on a sphere parameterized by central projection onto an icosahedron, where the
// answer is known.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "mesh/errors.h"
#include "mesh/primitives.h"
#include "mesh/topology.h"
#include "mesh/vertex_stars.h"
#include "remesh/base_domain.h"
#include "remesh/base_lift.h"
#include "tests/remesh/remesh_shapes.h"

namespace mrsnake {
namespace {

constexpr double kPi = 3.14159265358979323846;

double angle_of(const Eigen::Vector2d& p) { return std::atan2(p.y(), p.x()); }

// The angle from u to w, counter-clockwise, in [0, 2π).
double turn(const Eigen::Vector2d& u, const Eigen::Vector2d& w) {
  const double a = angle_of(w) - angle_of(u);
  return a < 0 ? a + 2 * kPi : a;
}

double angle_3d(const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

Eigen::Vector3d random_bary(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double s = u(rng), t = u(rng);
  if (s + t > 1) s = 1 - s, t = 1 - t;
  return {1 - s - t, s, t};
}

// A regular hexagon around its centre, in a tilted plane, stays a regular hexagon of the same
// radius, its first vertex on the x axis.
TEST(FlattenStar, ARegularHexagonAroundAPlanarCentreStaysRegular) {
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d center(0.5, -1, 2);
  std::vector<Eigen::Vector3d> ring;
  for (int k = 0; k < 6; ++k)
    ring.push_back(center + tilt * Eigen::Vector3d(2 * std::cos(k * kPi / 3), 2 * std::sin(k * kPi / 3), 0));
  const std::vector<Eigen::Vector2d> flat = flatten_star(center, ring, true);
  ASSERT_EQ(flat.size(), 6u);
  for (int k = 0; k < 6; ++k) {
    EXPECT_NEAR(flat[k].x(), 2 * std::cos(k * kPi / 3), 1e-12);
    EXPECT_NEAR(flat[k].y(), 2 * std::sin(k * kPi / 3), 1e-12);
  }
}

// At the apex of a skewed pyramid the angles fall short of 2π; flattened, each wedge keeps its
// share of the total and the wedges close the full turn.
TEST(FlattenStar, AConeVertexGetsAnglesSummingTwoPiInProportion) {
  const Eigen::Vector3d apex(0.3, -0.2, 0.8);
  const std::vector<Eigen::Vector3d> ring = {{1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {-1, -1, 0}};
  double total = 0;
  std::vector<double> angles;
  for (int i = 0; i < 4; ++i) angles.push_back(angle_3d(ring[i] - apex, ring[(i + 1) % 4] - apex));
  for (double a : angles) total += a;
  ASSERT_LT(total, 2 * kPi - 0.5);
  const std::vector<Eigen::Vector2d> flat = flatten_star(apex, ring, true);
  double sum = 0;
  for (int i = 0; i < 4; ++i) {
    const double wedge = turn(flat[i], flat[(i + 1) % 4]);
    EXPECT_NEAR(wedge, angles[i] * 2 * kPi / total, 1e-12);
    sum += wedge;
  }
  EXPECT_NEAR(sum, 2 * kPi, 1e-12);
}

// On a boundary, the ring from one boundary neighbour to the other spans exactly π.
TEST(FlattenStar, ABoundaryStarSpansExactlyPi) {
  const Eigen::Vector3d center(1, 1, 1);
  std::vector<Eigen::Vector3d> ring;
  for (double degrees : {0.0, 40.0, 100.0, 150.0}) {
    const double a = degrees * kPi / 180;
    ring.push_back(center + Eigen::Vector3d(std::cos(a), std::sin(a), 0.3 * std::sin(a)));
  }
  const std::vector<Eigen::Vector2d> flat = flatten_star(center, ring, false);
  EXPECT_NEAR(angle_of(flat[0]), 0, 1e-12);
  EXPECT_NEAR(flat[3].y(), 0, 1e-12);
  EXPECT_LT(flat[3].x(), 0);
  EXPECT_NEAR(turn(flat[0], flat[1]) + turn(flat[1], flat[2]) + turn(flat[2], flat[3]), kPi, 1e-12);
}

// The base meshes of the chart tests: a closed one and two disks (the finer one has boundary
// vertices with a single face).
std::vector<TriMesh> bases() {
  const TriMesh cap = test::spherical_cap(1), fine_cap = test::spherical_cap(2);
  EXPECT_TRUE(topology_report(cap).is_disk());
  EXPECT_TRUE(topology_report(fine_cap).is_disk());
  return {icosphere(0), cap, fine_cap};
}

// p named by face f at the barycentric coordinates `bary` of f's corners.
BasePoint at(int f, const Eigen::Vector3d& bary) { return BasePoint{f, bary}; }

TEST(BaseDomain, ChartRoundTripsRandomPointsInEveryStar) {
  std::mt19937 rng(1);
  for (const TriMesh& base : bases()) {
    const BaseDomain domain(base);
    for (int f = 0; f < base.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int v = base.F(f, k);
        for (int i = 0; i < 20; ++i) {
          const BasePoint p = at(f, random_bary(rng));
          ASSERT_TRUE(domain.in_star(v, p));
          const std::optional<BasePoint> back = domain.from_chart(v, domain.to_chart(v, p));
          ASSERT_TRUE(back.has_value());
          EXPECT_LT((domain.position(*back) - domain.position(p)).norm(), 1e-12);
          EXPECT_GE(back->bary.minCoeff(), 0);
        }
      }
  }
}

// Every star face is counter-clockwise and not a sliver in its vertex's chart (a lone boundary
// face too), and a point outside the star's polygon is not in the star.
TEST(BaseDomain, ChartsAreUnflippedAndBounded) {
  for (const TriMesh& base : bases()) {
    const BaseDomain domain(base);
    for (int f = 0; f < base.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int v = base.F(f, k);
        Eigen::Vector2d c[3];
        for (int j = 0; j < 3; ++j) c[j] = domain.to_chart(v, at(f, Eigen::Vector3d::Unit(j)));
        EXPECT_EQ(c[k], Eigen::Vector2d::Zero());
        const Eigen::Vector2d e1 = c[1] - c[0], e2 = c[2] - c[0];
        const double longest = std::max({e1.squaredNorm(), e2.squaredNorm(), (c[2] - c[1]).squaredNorm()});
        EXPECT_GT((e1.x() * e2.y() - e1.y() * e2.x()) / longest, 0.05) << "face " << f << " in the chart of " << v;
      }
    EXPECT_FALSE(domain.from_chart(0, Eigen::Vector2d(1e3, 1e3)).has_value());
  }
}

// in_star, against the mesh's adjacency: an interior point of a face is in the stars of its
// corners; a point on an edge also in the star of the face across's third corner; a corner in
// its own star and its neighbours'.
TEST(BaseDomain, InStarFollowsTheFacesAroundEdgesAndVertices) {
  for (const TriMesh& base : bases()) {
    const BaseDomain domain(base);
    const VertexStars stars(base.F, base.num_vertices());
    const auto has = [&](int f, int v) { return f >= 0 && (base.F.row(f).array() == v).any(); };
    const auto adjacent = [&](int a, int v) {
      return face_with_directed_edge(stars, base.F, a, v) >= 0 || face_with_directed_edge(stars, base.F, v, a) >= 0;
    };
    for (int f = 0; f < base.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = base.F(f, k), b = base.F(f, (k + 1) % 3);
        const int across = face_with_directed_edge(stars, base.F, b, a);
        Eigen::Vector3d on_edge = Eigen::Vector3d::Zero();
        on_edge[k] = 0.3, on_edge[(k + 1) % 3] = 0.7;
        for (int v = 0; v < base.num_vertices(); ++v) {
          EXPECT_EQ(domain.in_star(v, at(f, Eigen::Vector3d(0.2, 0.3, 0.5))), has(f, v));
          EXPECT_EQ(domain.in_star(v, at(f, on_edge)), has(f, v) || has(across, v));
          EXPECT_EQ(domain.in_star(v, at(f, Eigen::Vector3d::Unit(k))), v == a || adjacent(a, v));
        }
      }
  }
}

// chart_point is in_star and to_chart in one: nullopt exactly where the star does not hold the
// point (inside a face, on an edge, at a corner), else the same chart position, bit for bit.
TEST(BaseDomain, ChartPointIsInStarThenToChart) {
  for (const TriMesh& base : bases()) {
    const BaseDomain domain(base);
    int held = 0, outside = 0;
    for (int f = 0; f < base.num_faces(); ++f)
      for (const Eigen::Vector3d& bary :
           {Eigen::Vector3d(0.2, 0.3, 0.5), Eigen::Vector3d(0.3, 0.7, 0.0), Eigen::Vector3d(0.0, 0.0, 1.0)})
        for (int v = 0; v < base.num_vertices(); ++v) {
          const BasePoint p = at(f, bary);
          const std::optional<Eigen::Vector2d> q = domain.chart_point(v, p);
          ASSERT_EQ(q.has_value(), domain.in_star(v, p));
          if (!q) {
            ++outside;
            continue;
          }
          ++held;
          EXPECT_EQ(*q, domain.to_chart(v, p));
        }
    EXPECT_GT(held, 0);
    EXPECT_GT(outside, held);  // a star holds a few faces of many
  }
}

// A point on an edge named by either face, or a vertex named by any face of its star, has
// one position in every chart that holds it.
TEST(BaseDomain, APointOnASharedEdgeHasOneChartPosition) {
  for (const TriMesh& base : bases()) {
    const BaseDomain domain(base);
    const VertexStars stars(base.F, base.num_vertices());
    for (int f = 0; f < base.num_faces(); ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = base.F(f, k), b = base.F(f, (k + 1) % 3);
        const int g = face_with_directed_edge(stars, base.F, b, a);
        if (g < 0) continue;
        Eigen::Vector3d in_f = Eigen::Vector3d::Zero(), in_g = Eigen::Vector3d::Zero();
        in_f[k] = 0.3, in_f[(k + 1) % 3] = 0.7;
        for (int j = 0; j < 3; ++j) in_g[j] = base.F(g, j) == a ? 0.3 : base.F(g, j) == b ? 0.7 : 0.0;
        const BasePoint p = at(f, in_f), q = at(g, in_g);
        EXPECT_LT((domain.position(p) - domain.position(q)).norm(), 1e-15);
        const BaseDomain::ChartList charts = domain.charts_holding(p);
        EXPECT_EQ(charts.size(), 4u);
        for (int v : charts) EXPECT_LT((domain.to_chart(v, p) - domain.to_chart(v, q)).norm(), 1e-14);
      }
    for (int v = 0; v < base.num_vertices(); ++v) {
      const BasePoint p = domain.vertex_point(v);
      EXPECT_EQ(domain.position(p), Eigen::Vector3d(base.V.row(v)));
      for (int i = stars.offset[v]; i < stars.offset[v + 1]; ++i) {
        const int g = stars.faces[i];
        const BasePoint q = at(g, Eigen::Vector3d::Unit(base.F(g, 0) == v ? 0 : base.F(g, 1) == v ? 1 : 2));
        for (int w : domain.charts_holding(p)) EXPECT_LT((domain.to_chart(w, p) - domain.to_chart(w, q)).norm(), 1e-14);
      }
    }
  }
}

// A triangle of points counter-clockwise in one face is positive, reversed negative; so is a
// small triangle across an edge, against its 3D orientation about the edge's mean normal.
TEST(BaseDomain, OrientationIsPositiveForCounterClockwisePoints) {
  for (const TriMesh& base : bases()) {
    const BaseDomain domain(base);
    const VertexStars stars(base.F, base.num_vertices());
    const auto normal = [&](int f) {
      const Eigen::Vector3d a = base.V.row(base.F(f, 0)), b = base.V.row(base.F(f, 1)), c = base.V.row(base.F(f, 2));
      return (b - a).cross(c - a).normalized();
    };
    for (int f = 0; f < base.num_faces(); ++f) {
      const BasePoint p0 = at(f, {0.8, 0.1, 0.1}), p1 = at(f, {0.1, 0.8, 0.1}), p2 = at(f, {0.1, 0.1, 0.8});
      EXPECT_GT(domain.orientation(p0, p1, p2), 0);
      EXPECT_LT(domain.orientation(p0, p2, p1), 0);
      for (int k = 0; k < 3; ++k) {
        const int a = base.F(f, k), b = base.F(f, (k + 1) % 3);
        const int g = face_with_directed_edge(stars, base.F, b, a);
        if (g < 0) continue;
        // Two points just inside f near the edge, one just inside g: in 3D, about the mean normal.
        Eigen::Vector3d s = Eigen::Vector3d::Constant(0.02), t = s, u = Eigen::Vector3d::Constant(0.02);
        s[k] = 0.68, s[(k + 1) % 3] = 0.3, t[k] = 0.3, t[(k + 1) % 3] = 0.68;
        for (int j = 0; j < 3; ++j)
          if (base.F(g, j) == a || base.F(g, j) == b) u[j] = 0.49;
        const BasePoint q[3] = {at(f, s), at(f, t), at(g, u)};
        const Eigen::Vector3d x0 = domain.position(q[0]), x1 = domain.position(q[1]), x2 = domain.position(q[2]);
        const double in_3d = (normal(f) + normal(g)).dot((x1 - x0).cross(x2 - x0));
        const double in_chart = domain.orientation(q[0], q[1], q[2]);
        EXPECT_GT(in_3d * in_chart, 0) << "edge " << a << "-" << b;
      }
    }
  }
}

// Points in faces with no common vertex have no common chart; faces sharing one vertex have
// that one; points near a corner of one face get that corner's chart.
TEST(BaseDomain, CommonChartIsTheSharedVertexOrNone) {
  const TriMesh base = icosphere(0);
  const BaseDomain domain(base);
  for (int f = 0; f < base.num_faces(); ++f)
    for (int g = 0; g < base.num_faces(); ++g) {
      int shared = 0, vertex = -1;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          if (base.F(f, i) == base.F(g, j)) ++shared, vertex = base.F(f, i);
      const BasePoint points[2] = {at(f, {0.2, 0.3, 0.5}), at(g, {0.6, 0.3, 0.1})};
      const int chart = domain.common_chart(points, 2);
      if (shared == 0) {
        EXPECT_EQ(chart, -1);
        EXPECT_TRUE(std::isnan(domain.orientation(points[0], points[1], points[1])));
      } else if (shared == 1) {
        EXPECT_EQ(chart, vertex);
      } else {
        EXPECT_TRUE(domain.in_star(chart, points[0]) && domain.in_star(chart, points[1]));
      }
    }
  for (int k = 0; k < 3; ++k) {
    const BasePoint near_corner = at(7, Eigen::Vector3d::Constant(0.05) + 0.85 * Eigen::Vector3d::Unit(k));
    EXPECT_EQ(domain.common_chart(&near_corner, 1), base.F(7, k));
  }
}

TEST(BaseDomain, ThrowsOnANonManifoldVertex) {
  // Two tetrahedra sharing vertex 0: its faces make two closed fans.
  TriMesh bowtie;
  bowtie.V.resize(7, 3);
  bowtie.V << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, -1, 0, 0, 0, -1, 0, 0, 0, -1;
  bowtie.F.resize(8, 3);
  bowtie.F << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3, 0, 5, 4, 0, 4, 6, 0, 6, 5, 4, 5, 6;
  EXPECT_THROW(BaseDomain{bowtie}, TopologyError);
}

// The K face hit by the ray from the origin through x, and the barycentric coordinates there.
BasePoint central_projection(const TriMesh& K, const Eigen::Vector3d& x) {
  BasePoint best;
  double best_min = -1e300;
  for (int f = 0; f < K.num_faces(); ++f) {
    Eigen::Matrix3d corners;
    for (int k = 0; k < 3; ++k) corners.col(k) = K.V.row(K.F(f, k)).transpose();
    Eigen::Vector3d bary = corners.inverse() * x;
    if (bary.sum() <= 0) continue;
    bary /= bary.sum();
    if (bary.minCoeff() > best_min) best_min = bary.minCoeff(), best = BasePoint{f, bary};
  }
  best.bary = best.bary.cwiseMax(0.0);
  best.bary /= best.bary.sum();
  return best;
}

// The sphere icosphere(3) parameterized over the icosahedron by central projection; `rotation`
// turns the input so that its triangles straddle the icosahedron's edges.
struct CentralSetup {
  explicit CentralSetup(const Eigen::Matrix3d& rotation) : domain(icosphere(0)) {
    input.V = input.V * rotation.transpose();
    for (int v = 0; v < input.num_vertices(); ++v)
      location.push_back(central_projection(domain.base(), input.V.row(v).transpose()));
  }
  TriMesh input = icosphere(3);
  BaseDomain domain;
  std::vector<BasePoint> location;
  double edge = (input.V.row(input.F(0, 0)) - input.V.row(input.F(0, 1))).norm();
};

// Over random points p of D: the largest angle between lift(p) and the direction of p on K,
// and the largest distance from p to the point of D the hit stands for (its coordinates
// applied to its corners' locations, in their common chart). Every hit is a face with valid
// coordinates. `gaps` counts the points off their hit by more than rounding.
struct LiftErrors {
  double angle = 0, domain = 0;
  int gaps = 0;
};
void add_lift_errors(const CentralSetup& s, const BaseLift& lift, int samples, LiftErrors& worst) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> face(0, s.domain.base().num_faces() - 1);
  for (int i = 0; i < samples; ++i) {
    const BasePoint p{face(rng), random_bary(rng)};
    const BaseLift::Hit hit = lift.locate(p);
    EXPECT_TRUE(hit.face >= 0 && hit.face < s.input.num_faces());
    EXPECT_GE(hit.bary.minCoeff(), 0);
    EXPECT_NEAR(hit.bary.sum(), 1, 1e-12);
    const Eigen::Vector3d x = lift.lift(p);
    EXPECT_LE(x.norm(), 1 + 1e-12);
    EXPECT_GE(x.norm(), 1 - s.edge * s.edge);  // on a chord triangle of the unit sphere
    const BasePoint corners[3] = {s.location[s.input.F(hit.face, 0)], s.location[s.input.F(hit.face, 1)],
                                  s.location[s.input.F(hit.face, 2)]};
    const int chart = s.domain.common_chart(corners, 3);
    ASSERT_TRUE(chart >= 0 && s.domain.in_star(chart, p));
    Eigen::Vector2d in_chart = Eigen::Vector2d::Zero();
    for (int k = 0; k < 3; ++k) in_chart += hit.bary[k] * s.domain.to_chart(chart, corners[k]);
    worst.angle = std::max(worst.angle, angle_3d(x, s.domain.position(p)));
    const double off = (in_chart - s.domain.to_chart(chart, p)).norm();
    worst.domain = std::max(worst.domain, off);
    if (off > 1e-12) ++worst.gaps;
  }
}

void expect_vertices_lift_to_themselves(const CentralSetup& s, const BaseLift& lift) {
  for (int v = 0; v < s.input.num_vertices(); ++v)
    EXPECT_LT((lift.lift(s.location[v]) - s.input.V.row(v).transpose()).norm(), 1e-9) << "vertex " << v;
}

// Aligned, every input triangle lies in one face of K, on which all charts agree up to an
// affine map: the triangles tile D, and the hit stands for p exactly. The lift is linear on
// each triangle where central projection is projective: they differ by a small fraction of an
// edge.
TEST(BaseLift, FindsTheExactTriangleWhenTrianglesLieInBaseFaces) {
  const CentralSetup s(Eigen::Matrix3d::Identity());
  const BaseLift lift(s.input, s.domain, s.location);
  EXPECT_EQ(lift.unmapped_triangles(), 0);
  expect_vertices_lift_to_themselves(s, lift);
  LiftErrors worst;
  add_lift_errors(s, lift, 5000, worst);
  std::printf("aligned: largest angle %.3g rad, domain error %.3g (edge %.3g)\n", worst.angle, worst.domain, s.edge);
  EXPECT_EQ(worst.gaps, 0);
  EXPECT_LT(worst.domain, 1e-12);
  EXPECT_LT(worst.angle, 0.05 * s.edge);
}

// Rotated, triangles straddle K's edges, each straight in its own chart only: where the chart
// switches from one end of a K edge to the other (near its midpoint), neighbours disagree and
// leave narrow gaps, whose points get the nearest triangle. Elsewhere the hit is exact, the
// lift stays within a fraction of an edge of central projection's inverse, and vertices still
// lift exactly.
TEST(BaseLift, InvertsCentralProjectionToWithinAnEdgeWhenTrianglesStraddleBaseEdges) {
  const CentralSetup s(Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix());
  const BaseLift lift(s.input, s.domain, s.location);
  EXPECT_EQ(lift.unmapped_triangles(), 0);
  expect_vertices_lift_to_themselves(s, lift);
  LiftErrors worst;
  add_lift_errors(s, lift, 20000, worst);
  std::printf("rotated: largest angle %.3g rad, domain error %.3g (edge %.3g), %d of 20000 points in gaps\n",
              worst.angle, worst.domain, s.edge, worst.gaps);
  EXPECT_LT(worst.angle, 0.25 * s.edge);
  EXPECT_LT(worst.domain, 0.15 * s.edge);
  EXPECT_LT(worst.gaps, 20000 / 100);

  std::mt19937 rng(3);
  std::uniform_int_distribution<int> face(0, s.domain.base().num_faces() - 1);
  std::vector<BasePoint> points;
  for (int i = 0; i < 100000; ++i) points.push_back(BasePoint{face(rng), random_bary(rng)});
  const auto start = std::chrono::steady_clock::now();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const BasePoint& p : points) sum += lift.lift(p);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("lift of %zu points: %.1f ms (%.2f us per point; checksum %.3f)\n", points.size(), 1e3 * seconds,
              1e6 * seconds / points.size(), sum.norm());
}

// A vertex located on the far side of K leaves its triangles without a common chart: they are
// counted and skipped, and a point in the hole they leave gets a nearby triangle, clamped.
TEST(BaseLift, SkipsTrianglesWithNoCommonChartAndFillsTheirHole) {
  CentralSetup s(Eigen::Matrix3d::Identity());
  const int moved = 500;
  const BasePoint original = s.location[moved];
  s.location[moved] = central_projection(s.domain.base(), -s.input.V.row(moved).transpose());
  const BaseLift lift(s.input, s.domain, s.location);
  EXPECT_EQ(lift.unmapped_triangles(), 6);
  const BaseLift::Hit hit = lift.locate(original);
  EXPECT_GE(hit.bary.minCoeff(), 0);
  EXPECT_NEAR(hit.bary.sum(), 1, 1e-12);
  EXPECT_LT((lift.lift(original) - s.input.V.row(moved).transpose()).norm(), 2 * s.edge);
}

}  // namespace
}  // namespace mrsnake
