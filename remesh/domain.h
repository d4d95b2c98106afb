#pragma once
/// \file domain.h
/// The parameter domain D and a triangulation embedded in it, with point location.
///
/// Points of D are 3-vectors so that one orientation test serves both domains: on the unit
/// sphere a point is a unit vector; in the unit disk the point (x, y) is stored as (x, y, 1).
/// In both cases det(a, b, c) > 0 means the triangle (a, b, c) is counter-clockwise seen from
/// outside (sphere) or from +z (disk).
#include <utility>
#include <vector>

#include "mesh/trimesh.h"
#include "mesh/vertex_stars.h"

namespace mrsnake {

enum class DomainKind { sphere, disk };

/// det(a, b, c): positive for a triangle of D that is not flipped.
inline double domain_orientation(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  // a·((b − a) × (c − a)) equals a·(b × c), but from the edges: for a triangle of size ε the
  // cross product of the corners is ~ε with rounding ~1e-16 across it, which swamps ε² below
  // ε ~ 1e-8, while the edges' cross product is ~ε² with rounding ~1e-16·ε.
  return a.dot((b - a).cross(c - a));
}

/// Brings a point back onto D: onto the sphere, or onto the plane z = 1 (and onto the unit
/// circle when `on_boundary`).
Eigen::Vector3d project_to_domain(DomainKind kind, const Eigen::Vector3d& p, bool on_boundary);

/// Number of faces of (D, F) with domain_orientation <= 0.
int count_flipped(const RowMatrixX3d& D, const RowMatrixX3i& F);

/// The directed edges a -> b of F, in face order, with no face running b -> a: the boundary,
/// each edge with its face on the left.
/// \pre `stars` are F's vertex stars.
std::vector<std::pair<int, int>> boundary_edges(const RowMatrixX3i& F, const VertexStars& stars);

/// For each vertex on `rim_edges` (boundary_edges), its neighbours along the boundary:
/// (previous, next), -1 where there is none (every entry off the boundary).
/// \pre every vertex of rim_edges is in [0, n).
std::vector<Eigen::Vector2i> rim_neighbours(const std::vector<std::pair<int, int>>& rim_edges, int n);

/// Vertices on a boundary edge (an edge used by one face).
/// \pre `stars` are F's vertex stars.
std::vector<bool> boundary_vertices(const RowMatrixX3i& F, const VertexStars& stars);

/// The same, building the stars of F's `num_vertices` vertices.
/// \pre every entry of F is in [0, num_vertices).
std::vector<bool> boundary_vertices(const RowMatrixX3i& F, int num_vertices);

/// A triangulation embedded in D (the parameterized input), with walking point location.
class DomainMesh {
 public:
  struct Location {
    int face = -1;
    Eigen::Vector3d barycentric = Eigen::Vector3d::Zero();  ///< in face's corner order, sum 1, >= 0
  };
  /// \pre D has one row per vertex, no face of F is flipped in D.
  DomainMesh(RowMatrixX3d D, RowMatrixX3i F);

  const RowMatrixX3d& positions() const { return D_; }
  const RowMatrixX3i& faces() const { return F_; }
  /// The face holding p (a point of D, any positive scale on the sphere), starting the walk
  /// at `hint`. Points outside a disk's triangulation (between its boundary chords and the
  /// circle) get the nearest point of the last face reached.
  Location locate(const Eigen::Vector3d& p, int hint) const;

 private:
  Location brute_force(const Eigen::Vector3d& p) const;
  RowMatrixX3d D_;
  RowMatrixX3i F_;
  RowMatrixX3i neighbor_;  ///< neighbor_(f, e): face across the edge opposite corner e, -1 on the boundary
  /// Per face, the cross products b×c, c×a, a×b of its corners: p's barycentric weight of
  /// corner e is p·edge_normal_(f, e), one dot product instead of a determinant per test.
  Eigen::Matrix<double, Eigen::Dynamic, 9, Eigen::RowMajor> edge_normal_;
};

}  // namespace mrsnake
