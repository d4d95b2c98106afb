#pragma once
/// \file parameterization.h
/// Maps a disk or closed genus-0 surface onto the domain D and measures its area distortion.
///
/// Disk: mean value coordinates (Floater) with the boundary on a circle by arc length
/// (Floater's theorem: no flipped triangle). Closed genus 0, either
/// - punctured: the star of one well-shaped vertex is removed, the rest is mapped to the unit
///   disk the same way (a discrete approximation of the conformal map of the punctured
///   sphere) and lifted onto the sphere by inverse stereographic projection with the removed
///   vertex at the pole; or
/// - two halves: the surface is cut into two disks of equal area along a principal plane (its
///   spikes smoothed away), each is mapped to the unit disk the same way, on its own core, and
///   lifted onto one hemisphere, the cut onto the equator (both disks put it on the circle by
///   arc length, so they agree there). The map is continuous, with a kink along the cut.
/// Either is then balanced by Möbius transformations until the area-weighted centroid sits at
/// the centre. No seam in D.
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

/// How a closed genus-0 surface is mapped onto the sphere.
enum class SphereMap {
  /// two_halves for surfaces of at least ParameterizationOptions::halves_from_faces faces,
  /// where the sparse solve dominates; punctured below. Either falls back to hierarchical when
  /// it flips a triangle or its area stretch spans more than 12 orders of magnitude (long
  /// protrusions); the summary's `sphere_map_fallback` says why.
  automatic,
  /// One vertex's star removed, the rest mapped to one disk: one sparse solve.
  punctured,
  /// Cut in two disks of equal area across a principal plane, one per hemisphere: two
  /// half-size solves, in parallel. Falls back to punctured when no principal plane cuts the
  /// surface into two disks, a half's solve fails, or a triangle flips or goes flat on the
  /// sphere (the summary's `sphere_map_fallback` says which).
  two_halves,
  /// Praun and Hoppe's hierarchical stretch-minimizing map (remesh/stretch_map.h): a
  /// tetrahedron refined by the vertex splits of a progressive mesh, each relaxed in the L2
  /// stretch. Protrusions keep domain area in proportion to their own.
  hierarchical
};

/// Why a one-chart sphere map failed (ParameterizationOptions::on_hierarchical_fallback).
struct OneChartFailure {
  int flipped = 0;                  ///< triangles it turned over
  double stretch_spread_log10 = 0;  ///< orders of magnitude its area stretch spans (may be infinite)
  /// The stretch spans more than 12 orders of magnitude: protrusions squeezed past what one
  /// chart holds, whether or not a triangle flipped.
  bool squeezed() const;
  /// What failed, in words: the flips, the squeeze, or both (the summary's
  /// `sphere_map_fallback`, after "hierarchical: ").
  std::string reason() const;
};

/// Called when a one-chart sphere map failed; returns whether the hierarchical map replaces it.
using HierarchicalFallbackFn = std::function<bool(const OneChartFailure&)>;

struct ParameterizationOptions {
  SphereMap sphere_map = SphereMap::automatic;
  /// With automatic: the face count from which the two-halves map is used (it solves faster on
  /// large inputs; docs/remesh.md, "Tuning knobs").
  int halves_from_faces = 100000;
  /// With automatic: called once, before the hierarchical map replaces a one-chart map that
  /// failed (the automatic domain starts the base-mesh route then, on the other core). If it
  /// returns false, parameterize() stops there and throws AlgorithmError.
  HierarchicalFallbackFn on_hierarchical_fallback;
};

/// The input surface T embedded in D.
struct Parameterization {
  DomainKind kind = DomainKind::sphere;
  SphereMap sphere_map = SphereMap::punctured;  ///< the map used (punctured or two_halves), when kind is sphere
  TriMesh surface;                              ///< the input, unreferenced vertices dropped
  RowMatrixX3d domain;                          ///< position in D of each vertex of `surface`
  Eigen::VectorXd face_stretch;                 ///< per face: A3D / A_D (the inverse of the paper's distortion d)
  Eigen::VectorXd vertex_stretch;               ///< per vertex: sum of incident A3D / sum of incident A_D
  std::vector<int> cut;    ///< with two_halves: the surface vertices on the cut, by index (they lie on one circle of D)
  nlohmann::json summary;  ///< method, distortion range, seconds
};

/// \pre input is a disk or a closed genus-0 surface, its faces consistently oriented.
/// \throw TopologyError if it is neither, or its faces are not consistently oriented.
/// \throw AlgorithmError if the solver fails, a triangle flips, or the distortion is extreme.
Parameterization parameterize(const TriMesh& input, const ParameterizationOptions& options = {});

/// Mean value coordinates of a disk (Floater 2003), the boundary fixed by arc length on the
/// circle of centre (0.5, 0.5) and radius 0.5: the map of CGAL's
/// Mean_value_coordinates_parameterizer_3 with its default border, assembled from the triangle
/// list and factored once with KLU. Returns one (u, v) row per vertex.
/// \pre disk is a topological disk without unreferenced vertices.
/// \throw AlgorithmError if the rim is not one loop, the system cannot be solved, or the
/// coordinates are not finite.
Eigen::MatrixX2d mean_value_disk_map(const TriMesh& disk);

namespace detail {
/// The cut cleanup of the two-halves map, exposed for tests. `side` (0 or 1 per face of a
/// closed manifold `mesh`) is changed in place: spikes (a side's 3D angle at a cut vertex
/// below 0.6π and below the other side's) move across, in up to 8 sweeps, then ears (faces
/// with three corners and two or three edges on the cut) move across.
/// \pre `mesh` is a closed, consistently oriented manifold; `side` has one entry, 0 or 1, per face.
/// \return the cut's 3D length; 0 if the moves emptied one side (no cut left); or -1 if a chord
///   is left (an edge inside one side with both ends on the cut: one of its faces would flip on
///   the sphere).
double smooth_cut(const TriMesh& mesh, std::vector<int>& side);
}  // namespace detail

/// The Möbius transformation of the unit sphere that sends the point a (|a| < 1) of the ball
/// to its centre, applied to the unit vector x.
Eigen::Vector3d mobius_to_center(const Eigen::Vector3d& a, const Eigen::Vector3d& x);

}  // namespace mrsnake
