// CGAL adapter: edge-collapse simplification.
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Bounded_normal_change_placement.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Count_stop_predicate.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Edge_length_cost.h>
#include <CGAL/Surface_mesh_simplification/Policies/Edge_collapse/Midpoint_placement.h>
#include <CGAL/Surface_mesh_simplification/edge_collapse.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

#include "mesh/errors.h"
#include "mesh/parallel.h"
#include "mesh/topology.h"
#include "mesh/vertex_stars.h"
#include "remesh/domain.h"
#include "remesh/simplify.h"

namespace mrsnake {
namespace {

// The halves stop this much above their share of the target; the last pass over the stitched
// surface takes the rest, the cut's strip of input-sized edges first (the shortest).
constexpr double kHalvesSlack = 1.05;

using Kernel = CGAL::Simple_cartesian<double>;
using Point_3 = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point_3>;
using VertexIndex = SurfaceMesh::Vertex_index;
namespace SMS = CGAL::Surface_mesh_simplification;

// Midpoint placement that never moves a boundary vertex: an edge with one end on the boundary
// collapses onto that end, an edge with both ends on it does not collapse, and neither does
// one that would join two boundary vertices by a new edge (the other half could make the same
// edge: four faces on it once stitched). A boundary vertex is one topologically (CGAL keeps
// that through every collapse), so a half's cut stays exactly where it was, to be stitched to
// the other half's.
class KeepBoundaryPlacement {
 public:
  template <class Profile>
  boost::optional<typename Profile::Point> operator()(const Profile& profile) const {
    const SurfaceMesh& sm = profile.surface_mesh();
    const bool on0 = static_cast<bool>(CGAL::is_border(profile.v0(), sm)),
               on1 = static_cast<bool>(CGAL::is_border(profile.v1(), sm));
    if (on0 && on1) return boost::none;
    if (!on0 && !on1) return midpoint_(profile);
    const VertexIndex keep = on0 ? profile.v0() : profile.v1(), gone = on0 ? profile.v1() : profile.v0();
    for (const auto w : CGAL::vertices_around_target(sm.halfedge(gone), sm)) {
      if (w == keep || !CGAL::is_border(w, sm)) continue;
      bool joined = false;
      for (const auto u : CGAL::vertices_around_target(sm.halfedge(keep), sm)) joined = joined || u == w;
      if (!joined) return boost::none;
    }
    return sm.point(keep);
  }

 private:
  SMS::Midpoint_placement<SurfaceMesh> midpoint_;
};

SurfaceMesh to_surface_mesh(const TriMesh& mesh, const std::vector<int>& faces) {
  SurfaceMesh sm;
  std::vector<VertexIndex> vertex(mesh.num_vertices());
  std::vector<bool> added(mesh.num_vertices(), false);
  for (int f : faces)
    for (int k = 0; k < 3; ++k) {
      const int v = mesh.F(f, k);
      if (!added[v]) {
        vertex[v] = sm.add_vertex(Point_3(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)));
        added[v] = true;
      }
    }
  for (int f : faces)
    if (sm.add_face(vertex[mesh.F(f, 0)], vertex[mesh.F(f, 1)], vertex[mesh.F(f, 2)]) == SurfaceMesh::null_face())
      throw AlgorithmError("the surface could not be built for simplification (face " + std::to_string(f) +
                           " is non-manifold); repair the mesh first");
  return sm;
}

// Shortest edges first, collapsed to their midpoints, never turning a face's normal by more
// than 90°: keeps triangles well shaped, which the parameterization needs.
template <class Placement>
void collapse_to_edges(SurfaceMesh& sm, std::size_t edges, const Placement& inner) {
  SMS::Count_stop_predicate<SurfaceMesh> stop(edges);
  SMS::Bounded_normal_change_placement<Placement> placement(inner);
  SMS::edge_collapse(sm, stop, CGAL::parameters::get_cost(SMS::Edge_length_cost<SurfaceMesh>()).get_placement(placement));
  sm.collect_garbage();
}

// Appends sm's vertices and faces to `points` and `faces`. With `shared`, a boundary vertex at
// the exact position of a boundary vertex of the other half is that vertex (its bits are the
// key: both halves copied them from the same input vertex). Returns false if one half has two
// boundary vertices at one position (the stitch would be ambiguous).
bool append(const SurfaceMesh& sm, std::vector<std::array<double, 3>>& points, std::vector<std::array<int, 3>>& faces,
            std::map<std::array<std::uint64_t, 3>, std::pair<int, int>>* shared, int half) {
  std::vector<int> index(sm.num_vertices(), -1);
  for (const auto v : sm.vertices()) {
    const Point_3& p = sm.point(v);
    const std::array<double, 3> xyz{p.x(), p.y(), p.z()};
    if (shared && static_cast<bool>(CGAL::is_border(v, sm))) {
      std::array<std::uint64_t, 3> key{};
      std::memcpy(key.data(), xyz.data(), sizeof key);
      const auto [it, inserted] = shared->emplace(key, std::make_pair(static_cast<int>(points.size()), half));
      if (!inserted) {
        if (it->second.second == half) return false;
        index[v.idx()] = it->second.first;
        continue;
      }
    }
    index[v.idx()] = static_cast<int>(points.size());
    points.push_back(xyz);
  }
  for (const auto f : sm.faces()) {
    std::array<int, 3> corners{};
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(sm.halfedge(f), sm)) {
      if (k < 3) corners[k] = index[v.idx()];
      ++k;
    }
    if (k != 3) throw AlgorithmError("the simplified surface has a non-triangular face");
    faces.push_back(corners);
  }
  return true;
}

TriMesh to_trimesh(const std::vector<std::array<double, 3>>& points, const std::vector<std::array<int, 3>>& faces) {
  TriMesh out;
  out.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) out.V.row(static_cast<Eigen::Index>(i)) << points[i][0], points[i][1], points[i][2];
  out.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i) out.F.row(static_cast<Eigen::Index>(i)) << faces[i][0], faces[i][1], faces[i][2];
  return out;
}

}  // namespace

std::optional<TriMesh> detail::simplify_in_halves(const TriMesh& mesh, int target_faces) {
  // Two halves across the bounding box's longest axis (faces by centroid, at the median),
  // each simplified on its own core with its cut kept exactly, then stitched along it.
  const int m = mesh.num_faces();
  const Eigen::RowVector3d extent = mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff();
  Eigen::Index axis = 0;
  extent.maxCoeff(&axis);
  std::vector<double> height(m);
  for (int f = 0; f < m; ++f) height[f] = mesh.V(mesh.F(f, 0), axis) + mesh.V(mesh.F(f, 1), axis) + mesh.V(mesh.F(f, 2), axis);
  std::vector<int> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::nth_element(order.begin(), order.begin() + m / 2, order.end(), [&](int a, int b) { return height[a] < height[b]; });
  const std::array<std::vector<int>, 2> half{std::vector<int>(order.begin(), order.begin() + m / 2),
                                             std::vector<int>(order.begin() + m / 2, order.end())};
  std::array<SurfaceMesh, 2> sm;
  const auto simplify_half = [&](int i) {
    sm[i] = to_surface_mesh(mesh, half[i]);
    std::size_t border = 0;
    for (const auto h : sm[i].halfedges()) border += sm[i].is_border(h);
    // Edges of a triangle mesh with B boundary edges: (3F + B) / 2.
    const double share = static_cast<double>(half[i].size()) / m;
    collapse_to_edges(sm[i], static_cast<std::size_t>(share * kHalvesSlack * target_faces * 1.5 + 0.5 * border),
                      KeepBoundaryPlacement());
  };
  run_both_in_parallel([&] { simplify_half(0); }, [&] { simplify_half(1); });
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<int, 3>> faces;
  std::map<std::array<std::uint64_t, 3>, std::pair<int, int>> cut;  // position -> vertex, half
  if (!append(sm[0], points, faces, &cut, 0) || !append(sm[1], points, faces, &cut, 1)) return std::nullopt;
  const TriMesh stitched = to_trimesh(points, faces);
  // The same closed surface: V - E + F with E = 3F / 2, over the referenced vertices.
  std::vector<bool> used(mesh.num_vertices(), false);
  for (int f = 0; f < m; ++f)
    for (int k = 0; k < 3; ++k) used[mesh.F(f, k)] = true;
  const int euler = static_cast<int>(std::count(used.begin(), used.end(), true)) - m / 2;
  const TopologyReport after = topology_report(stitched);
  if (!(after.is_manifold() && after.is_closed() && after.components == 1 && after.euler_characteristic == euler))
    return std::nullopt;
  // The last pass over the whole surface: the cut's strip of input-sized edges (the shortest)
  // goes first.
  std::vector<int> all(stitched.num_faces());
  std::iota(all.begin(), all.end(), 0);
  SurfaceMesh whole = to_surface_mesh(stitched, all);
  collapse_to_edges(whole, static_cast<std::size_t>(target_faces) * 3 / 2, SMS::Midpoint_placement<SurfaceMesh>());
  points.clear();
  faces.clear();
  append(whole, points, faces, nullptr, 0);
  return to_trimesh(points, faces);
}

TriMesh simplify_to_faces(const TriMesh& mesh, int target_faces, const SimplifyOptions& options) {
  // Halves only for a closed surface: a disk's own rim would be kept whole too.
  if (options.halves_from_faces > 0 && mesh.num_faces() >= options.halves_from_faces &&
      boundary_edges(mesh.F, VertexStars(mesh.F, mesh.num_vertices())).empty())
    if (std::optional<TriMesh> halves = detail::simplify_in_halves(mesh, target_faces)) return std::move(*halves);
  // One core (also when the halves did not stitch: repeated positions on the cut, or a
  // zero-length edge that CGAL collapsed without asking the placement).
  std::vector<int> all(mesh.num_faces());
  std::iota(all.begin(), all.end(), 0);
  SurfaceMesh whole = to_surface_mesh(mesh, all);
  collapse_to_edges(whole, static_cast<std::size_t>(target_faces) * 3 / 2, SMS::Midpoint_placement<SurfaceMesh>());
  std::vector<std::array<double, 3>> points;
  std::vector<std::array<int, 3>> faces;
  append(whole, points, faces, nullptr, 0);
  return to_trimesh(points, faces);
}

}  // namespace mrsnake
