// The base-mesh domain (ParameterDomain::base_mesh): MAPS, the levels in the charts of K, and
// remesh() on it, on shapes whose one-chart maps onto the sphere are extreme.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "mesh/quality.h"
#include "mesh/subdivision.h"
#include "mesh/topology.h"
#include "remesh/base_levels.h"
#include "remesh/domain.h"
#include "remesh/maps.h"
#include "remesh/remesh.h"
#include "remesh/remesh_options_json.h"
#include "tests/remesh/remesh_shapes.h"
#include "tests/test_support.h"

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
  // The report's summary names the steps that ran: the base mesh has no Lloyd step in D.
  const nlohmann::json report = remesh_report(r, base_domain_options(4000));
  EXPECT_EQ(report["lloyd_iterations"], 0);
  EXPECT_EQ(report["options"]["relaxation"]["lloyd_iterations"], 8);  // the run, to repeat it
  EXPECT_EQ(report["guarded_shape_iterations"], 8);                   // in the Lloyd step's place
  // Nor a repair of its coarse levels, whatever the option asks.
  EXPECT_EQ(report["repair_coarse_levels"], false);
  EXPECT_EQ(report["options"]["repair"]["coarse_levels"], true);
  // It repairs on the surface it parameterized, before any projection onto the original.
  EXPECT_EQ(report["repair_after_reprojection"], false);
}

TEST(BaseDomainRemesh, ACoarseInputIsSplitFlatSoTheFinestLevelsTrianglesHoldTheirShape) {
  // 320 faces for a finest level of about 5000: split 1:4 until it has the level's faces,
  // on its own surface. Lifted through triangles larger than the level's, whose charts kink
  // across K's edges, the finest level would have collapsed triangles.
  const TriMesh input = test::ellipsoid(2);
  const RemeshResult r = remesh(input, base_domain_options(5000));
  const int finest = r.connectivity.levels();
  const long long finest_faces = r.connectivity.faces[finest].rows();
  long long split = input.num_faces();
  while (split < finest_faces) split *= 4;
  EXPECT_EQ(r.parameterization["parameterized_faces"].get<long long>(), split);
  expect_valid_hierarchy(r, input);
  const nlohmann::json q = mesh_quality(r.mesh(finest));
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

// K as its own input, split once: each new vertex lifts to its parents' 3D midpoint, as every
// face of K is flat. With one parent moved to a face that no chart of the other reaches, the
// split reports the edge instead of placing a midpoint.
TEST(BaseLevels, SplitPlacesMidpointsAndReportsAnEdgeWithNoChart) {
  const TriMesh K = icosphere(0);
  const BaseDomain domain(K);
  std::vector<BasePoint> location;
  for (int v = 0; v < K.num_vertices(); ++v) location.push_back(domain.vertex_point(v));
  const BaseLift lift(K, domain, location);
  const SubdivisionConnectivity c = subdivide_connectivity(K.F, K.num_vertices(), 1);
  const BaseLayout start = base_vertices_layout(domain, lift);
  BaseLayout layout = start;
  ASSERT_TRUE(split_on_base(c, 1, domain, lift, layout));
  ASSERT_EQ(static_cast<int>(layout.points.size()), c.vertex_count(1));
  for (int v = c.vertex_count(0); v < c.vertex_count(1); ++v) {
    const Eigen::Vector2i p = c.parents(v);
    const Eigen::RowVector3d mid = 0.5 * (K.V.row(p[0]) + K.V.row(p[1]));
    EXPECT_LT((layout.X.row(v) - mid).norm(), 1e-9) << "vertex " << v;
  }
  // A face with no corner in the closed star of b, the second parent of the first new vertex.
  const Eigen::Vector2i p = c.parents(c.vertex_count(0));
  const auto has = [&](int f, int w) { return K.F(f, 0) == w || K.F(f, 1) == w || K.F(f, 2) == w; };
  const auto near_b = [&](int w) {
    for (int f = 0; f < K.num_faces(); ++f)
      if (has(f, p[1]) && has(f, w)) return true;
    return false;
  };
  int far_face = -1;
  for (int f = 0; f < K.num_faces() && far_face < 0; ++f)
    if (!near_b(K.F(f, 0)) && !near_b(K.F(f, 1)) && !near_b(K.F(f, 2))) far_face = f;
  ASSERT_GE(far_face, 0);
  BaseLayout moved = start;
  moved.points[p[0]] = BasePoint{far_face, Eigen::Vector3d::Constant(1.0 / 3)};
  EXPECT_FALSE(split_on_base(c, 1, domain, lift, moved));
}

double smallest_q(const RowMatrixX3d& X, const RowMatrixX3i& F) {
  double q = 1;
  for (int f = 0; f < F.rows(); ++f)
    q = std::min(
        q, frey_borouchaki_quality(X.row(F(f, 0)).transpose(), X.row(F(f, 1)).transpose(), X.row(F(f, 2)).transpose()));
  return q;
}

// An input's MAPS remesh with `base_vertices` base vertices, split twice in the base domain;
// each level relaxed (smooth_on_base's defaults) if `relaxed`, else every vertex at dyadic
// barycentric coordinates of one face of K. No triangle is flipped in D.
struct TwiceSplitLevel {
  TriMesh input;
  MapsParameterization maps;
  BaseDomain domain;
  BaseLift lift;
  SubdivisionConnectivity c;
  BaseLayout layout;

  static MapsParameterization simplified(const TriMesh& input, int base_vertices) {
    MapsOptions options;
    options.base_vertices = base_vertices;
    return maps_parameterize(input, options);
  }
  TwiceSplitLevel(TriMesh surface, int base_vertices, bool relaxed)
      : input(std::move(surface)),
        maps(simplified(input, base_vertices)),
        domain(maps.base),
        lift(input, domain, maps.location),
        c(subdivide_connectivity(maps.base.F, maps.base.num_vertices(), 2)),
        layout(base_vertices_layout(domain, lift)) {
    for (int j = 1; j <= 2; ++j) {
      if (!split_on_base(c, j, domain, lift, layout)) throw std::logic_error("split");
      if (relaxed) smooth_on_base(c.faces[j], domain, lift, layout, BaseSmoothingOptions{});
    }
    if (count_flipped_on_base(domain, finest(), layout.points) != 0) throw std::logic_error("flipped");
  }
  const RowMatrixX3i& finest() const { return c.faces[2]; }
};

// The MAPS remesh of a capsule (the dyadic split of K, unrelaxed) has poor triangles where K's
// faces are; the repair raises the worst of them, adds no flip in D, and leaves every vertex
// exactly on the input (the lift of its point of D), with and without the surface guard.
TEST(BaseLevels, RepairRaisesTheWorstQualityOnTheInputWithoutAFlip) {
  const TwiceSplitLevel capsule(test::capsule(6.0, 24), 40, /*relaxed=*/false);
  const RowMatrixX3i& F = capsule.finest();
  const double before = smallest_q(capsule.layout.X, F);
  ASSERT_LT(before, 0.5);
  for (const double tolerance : {-1.0, 0.03}) {
    SCOPED_TRACE("error tolerance " + std::to_string(tolerance));
    BaseLayout layout = capsule.layout;
    BaseRepairOptions options;
    options.error_tolerance = tolerance;
    const BaseRepairStats stats = repair_on_base(F, capsule.domain, capsule.lift, layout, options);
    EXPECT_GT(stats.moves, 0);
    EXPECT_DOUBLE_EQ(stats.q_min_before, before);
    EXPECT_DOUBLE_EQ(stats.q_min_after, smallest_q(layout.X, F));
    EXPECT_GT(stats.q_min_after, before + 0.05) << stats.q_min_after;
    EXPECT_EQ(count_flipped_on_base(capsule.domain, F, layout.points), 0);
    double off = 0;
    for (std::size_t v = 0; v < layout.points.size(); ++v)
      off = std::max(off, (layout.X.row(v).transpose() - capsule.lift.lift(layout.points[v])).norm());
    EXPECT_EQ(off, 0.0);
  }
}

// Shape smoothing with a floor of 1 (the guarded sweeps): a move never lowers the smallest Q
// of its vertex's triangles, and those are the only triangles it changes, so the level's
// smallest Q never falls, while its mean rises; nothing flips. Here a free sweep lowers it.
TEST(BaseLevels, GuardedShapeSweepsNeverLowerTheSmallestQuality) {
  const TwiceSplitLevel capsule(test::capsule(6.0, 24), 20, /*relaxed=*/false);
  const BaseDomain& domain = capsule.domain;
  const BaseLift& lift = capsule.lift;
  const BaseLayout& split = capsule.layout;
  const RowMatrixX3i& F = capsule.finest();
  BaseSmoothingOptions sweep;
  sweep.iterations = 1;
  BaseLayout free_sweep = split;
  smooth_on_base(F, domain, lift, free_sweep, sweep);
  EXPECT_LT(smallest_q(free_sweep.X, F), smallest_q(split.X, F) - 0.05);

  BaseLayout layout = split;
  sweep.quality_floor = 1.0;
  int moves = 0;
  for (int i = 0; i < 6; ++i) {
    const double smallest = smallest_q(layout.X, F);
    moves += smooth_on_base(F, domain, lift, layout, sweep);
    EXPECT_GE(smallest_q(layout.X, F), smallest) << "sweep " << i;
    EXPECT_EQ(count_flipped_on_base(domain, F, layout.points), 0);
  }
  EXPECT_GT(moves, 0);
  EXPECT_GT(mesh_quality(TriMesh{layout.X, F}).q_mean, mesh_quality(TriMesh{split.X, F}).q_mean + 0.01);
}

// An ellipsoid with a spike at one end of its long axis.
TriMesh spiked_ellipsoid() {
  TriMesh m = test::ellipsoid(4);
  Eigen::Index tip = 0;
  m.V.col(0).maxCoeff(&tip);
  m.V.row(tip) *= 1.15;
  return m;
}

// That ellipsoid's MAPS remesh split twice and relaxed in the base domain: the relaxation pulls
// the vertices off the spike, and the level cuts it off.
struct RelaxedEllipsoidLevel : TwiceSplitLevel {
  RelaxedEllipsoidLevel() : TwiceSplitLevel(spiked_ellipsoid(), 30, /*relaxed=*/true) {}
};

// The snap in the base domain: vertices move exactly onto input vertices at their own points
// of D, the largest input-to-level distance goes down, and nothing flips. A gain no snap can
// give refuses them all and leaves the layout as it was.
TEST(BaseLevels, SnapPutsVerticesExactlyOnTheTipsTheLevelCutsOff) {
  RelaxedEllipsoidLevel level;
  const RowMatrixX3i& F = level.c.faces[2];
  BaseLayout& layout = level.layout;
  const BaseLayout before = layout;
  const double cut = SurfaceLocator(TriMesh{layout.X, F}).distances(level.input.V).maxCoeff();
  std::vector<bool> snapped;
  FeatureSnapOptions options;  // a tip this sharp would leave triangles below the default bounds
  options.min_quality = 0.2;
  options.min_angle_deg = 10;
  const int snaps = snap_on_base(F, level.domain, level.lift, layout, options, &snapped);
  EXPECT_GT(snaps, 0);
  EXPECT_LT(SurfaceLocator(TriMesh{layout.X, F}).distances(level.input.V).maxCoeff(), 0.75 * cut);
  EXPECT_EQ(count_flipped_on_base(level.domain, F, layout.points), 0);
  int moved = 0;
  for (std::size_t v = 0; v < layout.points.size(); ++v) {
    if (!snapped[v]) {
      EXPECT_TRUE(layout.X.row(v) == before.X.row(v));
      continue;
    }
    ++moved;
    int at = -1;
    for (int s = 0; s < level.input.num_vertices(); ++s)
      if (level.input.V.row(s) == layout.X.row(v)) at = s;
    ASSERT_GE(at, 0) << "vertex " << v << " is no input vertex";
    EXPECT_EQ(layout.points[v].face, level.maps.location[at].face);
    EXPECT_TRUE(layout.points[v].bary == level.maps.location[at].bary);
  }
  EXPECT_EQ(moved, snaps);

  RelaxedEllipsoidLevel again;
  FeatureSnapOptions all_or_nothing = options;
  all_or_nothing.min_gain = 1.0;
  EXPECT_EQ(snap_on_base(F, again.domain, again.lift, again.layout, all_or_nothing, &snapped), 0);
  EXPECT_TRUE(again.layout.X == before.X);
  for (std::size_t v = 0; v < before.points.size(); ++v) {
    EXPECT_EQ(again.layout.points[v].face, before.points[v].face);
    EXPECT_TRUE(again.layout.points[v].bary == before.points[v].bary);
  }
}

// The octopus's tentacles stretch relaxed slivers across more than one chart of K, or fold
// them, so that some levels start over from the dyadic split: the run goes on, unflipped. (Once
// no level of it needs to, it no longer exercises the fallback: take a harder input.)
TEST(BaseDomainRemesh, ALevelWhoseRelaxedSplitFailsStartsFromTheDyadicSplit) {
  MRSNAKE_REQUIRE_DATA(path, "meshes/octopus.off");
  const TriMesh input = read_mesh(path);
  const RemeshResult r = remesh(input, base_domain_options(16000));
  int restarted = 0;
  for (const RemeshLevel& level : r.levels) {
    EXPECT_EQ(level.flipped_triangles, 0);
    if (level.stats["level"].get<int>() > 0 && level.stats["started_from"] == "dyadic split") ++restarted;
  }
  EXPECT_GE(restarted, 1);
}

// A flat disk whose rim wobbles, radius 1 + 0.25 sin 7θ, as a polar grid: `rings` rings of
// `around` vertices around a centre.
TriMesh wavy_disk(int rings, int around) {
  const double pi = 3.14159265358979323846;
  TriMesh m;
  m.V.resize(rings * around + 1, 3);
  m.V.row(0).setZero();
  for (int i = 1; i <= rings; ++i)
    for (int k = 0; k < around; ++k) {
      const double a = 2 * pi * k / around, r = (1 + 0.25 * std::sin(7 * a)) * i / rings;
      m.V.row((i - 1) * around + k + 1) << r * std::cos(a), r * std::sin(a), 0;
    }
  std::vector<Eigen::RowVector3i> faces;
  const auto at = [&](int i, int k) { return i == 0 ? 0 : (i - 1) * around + (k % around) + 1; };
  for (int k = 0; k < around; ++k) {
    faces.emplace_back(0, at(1, k), at(1, k + 1));
    for (int i = 1; i < rings; ++i) {
      faces.emplace_back(at(i, k), at(i + 1, k), at(i + 1, k + 1));
      faces.emplace_back(at(i, k), at(i + 1, k + 1), at(i, k + 1));
    }
  }
  m.F.resize(static_cast<int>(faces.size()), 3);
  for (std::size_t f = 0; f < faces.size(); ++f) m.F.row(static_cast<int>(f)) = faces[f];
  return m;
}

// The distance from x to the nearest boundary edge of (V, F).
double distance_to_rim(const TriMesh& mesh, const Eigen::Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& [a, b] : boundary_edges(mesh.F, VertexStars(mesh.F, mesh.num_vertices()))) {
    const Eigen::Vector3d p = mesh.V.row(a), e = mesh.V.row(b).transpose() - p;
    const double t = std::clamp((x - p).dot(e) / e.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (x - p - t * e).norm());
  }
  return best;
}

// The rim's edge length ratio (longest / shortest).
double rim_length_ratio(const TriMesh& mesh) {
  std::vector<double> lengths;
  for (const auto& [a, b] : boundary_edges(mesh.F, VertexStars(mesh.F, mesh.num_vertices())))
    lengths.push_back((mesh.V.row(a) - mesh.V.row(b)).norm());
  const auto [shortest, longest] = std::minmax_element(lengths.begin(), lengths.end());
  return *longest / *shortest;
}

TEST(BaseDomainRemesh, ADiskRimSlidesAlongTheInputRimToEvenLengths) {
  const TriMesh input = wavy_disk(24, 160);
  ASSERT_TRUE(topology_report(input).is_disk());
  const RemeshResult r = remesh(input, base_domain_options(4000));
  const double diag = bounding_box_diagonal(input.V);
  const int finest = r.connectivity.levels();
  for (int j = 0; j <= finest; ++j) {
    SCOPED_TRACE("level " + std::to_string(j));
    const TriMesh level = r.mesh(j);
    EXPECT_EQ(r.levels[j].flipped_triangles, 0);
    EXPECT_TRUE(topology_report(level).is_disk());
    for (const auto& [a, b] : boundary_edges(level.F, VertexStars(level.F, level.num_vertices())))
      EXPECT_LT(distance_to_rim(input, level.V.row(a).transpose()), 1e-9 * diag);
  }
  // The rim's edges at the finest level: a fixed rim keeps the spacing of K's rim edges split
  // evenly in D, which the wobble stretches unevenly in 3D (longest / shortest 3.4 here);
  // sliding evens them (1.8).
  EXPECT_LT(rim_length_ratio(r.mesh(finest)), 2.2);
}

TEST(BaseDomainRemesh, WithSmoothRimOffTheRimVerticesStayWhereTheSplitPutThem) {
  const TriMesh input = wavy_disk(24, 160);
  RemeshOptions o = base_domain_options(4000);
  o.relaxation.smooth_rim = false;
  const RemeshResult r = remesh(input, o);
  const TriMesh coarse = r.mesh(0), fine = r.mesh(r.connectivity.levels());
  // K's rim vertices are the first rows of every level: with the rim held they never move.
  for (const auto& [a, b] : boundary_edges(coarse.F, VertexStars(coarse.F, coarse.num_vertices())))
    EXPECT_LT((fine.V.row(a) - coarse.V.row(a)).norm(), 1e-12) << "rim vertex " << a;
  EXPECT_GT(rim_length_ratio(fine), 3.0);  // the uneven spacing the sliding evens (see above)
  EXPECT_EQ(remesh_report(r, o)["smooth_rim"], false);
}

// The automatic domain (the default): a capsule long enough that the one-chart sphere map
// fails is built on both domains, the base mesh's on another thread, and the kept one is the
// better by the rule it records; an ellipsoid, which one chart holds, stays on the sphere with
// no second build. (The capsule's one-chart map fails by its squeeze, which by default builds
// the base mesh alone: the next test. Both are built by default where the map only flipped.)
TEST(AutomaticDomain, AShapeOneChartCannotHoldKeepsTheBetterOfBothDomains) {
  RemeshOptions o;
  o.base_mesh_alone_when_squeezed = false;
  o.target_faces = 4096;
  o.compute_stats = false;  // measured after the choice, out of the times checked below
  std::map<std::thread::id, std::vector<std::string>> stages_by_thread;
  std::atomic<int> reporting{0};
  int most_reporting = 0;
  o.progress = [&](const std::string& stage, double) {
    most_reporting = std::max(most_reporting, ++reporting);
    std::this_thread::sleep_for(std::chrono::microseconds(200));  // a window for a second caller
    std::vector<std::string>& stages = stages_by_thread[std::this_thread::get_id()];
    if (stages.empty() || stages.back() != stage) stages.push_back(stage);
    --reporting;
  };
  const TriMesh capsule = test::capsule(40.0);
  const auto call_start = std::chrono::steady_clock::now();
  const RemeshResult r = remesh(capsule, o);
  const double call_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - call_start).count();
  // Both domains report through one lock, the base mesh's from another thread, and its stages
  // say which domain they are; in each domain, no stage name comes twice.
  EXPECT_EQ(most_reporting, 1);
  ASSERT_EQ(stages_by_thread.size(), 2u);
  for (const auto& [thread, stages] : stages_by_thread) {
    const bool caller = thread == std::this_thread::get_id();
    const std::set<std::string> distinct(stages.begin(), stages.end());
    EXPECT_EQ(distinct.size(), stages.size());
    EXPECT_TRUE(distinct.count(caller ? "parameterize" : "base-mesh domain: parameterize"));
    for (const std::string& stage : stages) EXPECT_EQ(stage.rfind("base-mesh domain: ", 0) == 0, !caller) << stage;
  }
  const nlohmann::json& choice = r.parameterization["domain_choice"];
  ASSERT_TRUE(choice.is_object()) << r.parameterization;
  EXPECT_NE(choice["sphere_map_fallback"].get<std::string>().find("hierarchical"), std::string::npos);
  EXPECT_EQ(choice["chosen"], r.domain);
  const nlohmann::json &kept = choice[r.domain], &other = choice[r.domain == "sphere" ? "base_mesh" : "sphere"];
  const TriMesh finest = r.mesh(static_cast<int>(r.levels.size()) - 1);
  EXPECT_EQ(kept["self_intersections"].get<int>(), count_self_intersections(finest));
  EXPECT_DOUBLE_EQ(kept["q_mean"].get<double>(), mesh_quality(finest).q_mean);
  const int kept_x = kept["self_intersections"], other_x = other["self_intersections"];
  EXPECT_TRUE(kept_x < other_x || (kept_x == other_x && kept["q_mean"] >= other["q_mean"])) << choice;
  expect_valid_hierarchy(r, capsule);
  // The time of the domain not kept counts in the total, which is the call's wall time: the
  // two domains overlap, and their stages' sum would count the overlap twice.
  EXPECT_GT(choice["seconds"].get<double>(), 0.0);
  const double total = remesh_report(r, o)["seconds"].get<double>();
  EXPECT_GE(total, choice["seconds"].get<double>() + r.parameterization["seconds"].get<double>());
  EXPECT_LE(total, call_seconds);
  EXPECT_GE(total, 0.9 * call_seconds);

  const RemeshResult plain = remesh(test::ellipsoid(3), o);
  EXPECT_EQ(plain.domain, "sphere");
  EXPECT_FALSE(plain.parameterization.contains("domain_choice"));
}

// Squeezed by the one-chart map (protrusions), a capsule is built on the base mesh alone: the
// sphere route stops at its one-chart map, and the result is the base-mesh domain's own. If the
// base mesh fails, the sphere route is built on the hierarchical map after all.
TEST(AutomaticDomain, AShapeTheOneChartMapSqueezesIsBuiltOnTheBaseMeshAlone) {
  RemeshOptions o;
  o.target_faces = 1024;
  std::set<std::string> failing_stages;
  std::vector<std::string> sphere_stages;  // the caller's: the sphere route's
  o.progress = [&](const std::string& stage, double) {
    if (failing_stages.count(stage)) throw AlgorithmError("no " + stage);
    if (stage.rfind("base-mesh domain: ", 0) != 0) sphere_stages.push_back(stage);
  };
  const TriMesh capsule = test::capsule(40.0);
  const RemeshResult r = remesh(capsule, o);
  ASSERT_EQ(r.domain, "base_mesh");
  const nlohmann::json& choice = r.parameterization["domain_choice"];
  EXPECT_NE(choice["sphere_map_fallback"].get<std::string>().find("orders of magnitude"), std::string::npos) << choice;
  EXPECT_TRUE(choice["sphere"].contains("skipped")) << choice;
  EXPECT_EQ(choice["chosen"], "base_mesh");
  EXPECT_EQ(choice["base_mesh"]["self_intersections"].get<int>(),
            count_self_intersections(r.mesh(static_cast<int>(r.levels.size()) - 1)));
  EXPECT_EQ(sphere_stages, std::vector<std::string>{"parameterize"});  // no level built on the sphere
  // The levels are the base-mesh domain's, as built alone.
  RemeshOptions alone = o;
  alone.domain = ParameterDomain::base_mesh;
  const RemeshResult on_base = remesh(capsule, alone);
  ASSERT_EQ(on_base.levels.size(), r.levels.size());
  for (std::size_t j = 0; j < r.levels.size(); ++j)
    EXPECT_EQ(r.levels[j].positions, on_base.levels[j].positions) << "level " << j;
  expect_valid_hierarchy(r, capsule);

  failing_stages.insert("base-mesh domain: level 0");
  const RemeshResult instead = remesh(capsule, o);
  ASSERT_EQ(instead.domain, "sphere");
  EXPECT_EQ(instead.parameterization["sphere_map"], "hierarchical");
  EXPECT_EQ(instead.parameterization["domain_choice"]["base_mesh"]["error"], "no base-mesh domain: level 0");
  EXPECT_EQ(instead.parameterization["domain_choice"]["chosen"], "sphere");
  expect_valid_hierarchy(instead, capsule);
}

// The input's large slivers are remeshed once, for both routes: the stage is reported once, by
// the caller's thread, and the base mesh's levels are those it builds alone (which remeshes
// them itself).
TEST(AutomaticDomain, BothRoutesStartFromOneRemeshingOfTheSlivers) {
  const TriMesh capsule = test::capsule(40.0, 16, 4.0);  // squeezed by one chart, its tube of slivers
  RemeshOptions o;
  o.target_faces = 1024;
  o.compute_stats = false;
  std::vector<std::string> sliver_stages;
  const std::thread::id caller = std::this_thread::get_id();
  bool other_thread = false;
  o.progress = [&](const std::string& stage, double fraction) {
    if (stage.find("remesh the slivers") != std::string::npos && fraction == 0) {
      sliver_stages.push_back(stage);
      other_thread = other_thread || std::this_thread::get_id() != caller;
    }
  };
  const RemeshResult r = remesh(capsule, o);
  ASSERT_EQ(r.domain, "base_mesh");
  EXPECT_TRUE(r.parameterization.at("sliver_remeshed").get<bool>());
  EXPECT_EQ(sliver_stages, std::vector<std::string>{"remesh the slivers"});
  EXPECT_FALSE(other_thread);
  RemeshOptions alone = o;
  alone.domain = ParameterDomain::base_mesh;
  alone.progress = nullptr;
  const RemeshResult on_base = remesh(capsule, alone);
  ASSERT_EQ(on_base.levels.size(), r.levels.size());
  for (std::size_t j = 0; j < r.levels.size(); ++j)
    EXPECT_EQ(r.levels[j].positions, on_base.levels[j].positions) << "level " << j;
}

// Where the sphere route fails (here its progress callback throws at its first level), the base
// mesh's result stands in: on a capsule it was built beside the hierarchical map (both domains
// built, as where the one-chart map only flips), on an ellipsoid (one chart holds it) it is built
// then. Either is measured as a kept domain is. Both failing report the sphere's error.
TEST(AutomaticDomain, TheBaseMeshStandsInWhereTheSphereRouteFails) {
  RemeshOptions o;
  o.base_mesh_alone_when_squeezed = false;
  o.target_faces = 1024;
  std::set<std::string> failing_stages = {"level 0"};
  o.progress = [&](const std::string& stage, double) {
    if (failing_stages.count(stage)) throw AlgorithmError("no " + stage);
  };
  for (const TriMesh& shape : {test::capsule(40.0), test::ellipsoid(3)}) {
    const RemeshResult r = remesh(shape, o);
    ASSERT_EQ(r.domain, "base_mesh");
    const nlohmann::json& choice = r.parameterization["domain_choice"];
    EXPECT_EQ(choice["sphere"]["error"], "no level 0");
    EXPECT_EQ(choice["chosen"], "base_mesh");
    EXPECT_EQ(choice["base_mesh"]["self_intersections"].get<int>(),
              count_self_intersections(r.mesh(static_cast<int>(r.levels.size()) - 1)));
    expect_valid_hierarchy(r, shape);
    for (int j = 0; j < static_cast<int>(r.levels.size()); ++j) {
      const nlohmann::json& stats = r.levels[j].stats;
      ASSERT_TRUE(stats.contains("quality") && stats.contains("distance")) << "level " << j;
      EXPECT_DOUBLE_EQ(stats["quality"]["q_mean"].get<double>(), mesh_quality(r.mesh(j)).q_mean);
    }
  }
  failing_stages.insert("base-mesh domain: level 0");
  try {
    remesh(test::capsule(40.0), o);
    ADD_FAILURE() << "both domains failed, and remesh returned";
  } catch (const AlgorithmError& e) {
    EXPECT_STREQ(e.what(), "no level 0");
  }
}

TEST(BaseDomainRemesh, OptionNameRoundTripsThroughJson) {
  RemeshOptions o = base_domain_options(1000);
  const nlohmann::json j = o;
  EXPECT_EQ(j["domain"], "base_mesh");
  EXPECT_EQ(j.get<RemeshOptions>().domain, ParameterDomain::base_mesh);
}

}  // namespace
}  // namespace mrsnake
