#pragma once
/// \file parameterization.h
/// Maps a disk or closed genus-0 surface onto the domain D and measures its area distortion.
///
/// Disk: CGAL mean value coordinates with the boundary on the unit circle by arc length
/// (Floater's theorem: no flipped triangle). Closed genus 0: the star of one well-shaped
/// vertex is removed, the rest is mapped to the unit disk the same way (a discrete
/// approximation of the conformal map of the punctured sphere), lifted onto the sphere by
/// inverse stereographic projection with the removed vertex at the pole, then balanced by
/// Möbius transformations until the area-weighted centroid sits at the centre. No seam.
#include <nlohmann/json.hpp>

#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

/// The input surface T embedded in D.
struct Parameterization {
  DomainKind kind = DomainKind::sphere;
  TriMesh surface;                 ///< the input, unreferenced vertices dropped
  RowMatrixX3d domain;             ///< position in D of each vertex of `surface`
  Eigen::VectorXd face_stretch;    ///< per face: A3D / A_D (the inverse of the paper's distortion d)
  Eigen::VectorXd vertex_stretch;  ///< per vertex: sum of incident A3D / sum of incident A_D
  nlohmann::json summary;          ///< method, distortion range, seconds
};

/// \pre input is a disk or a closed genus-0 surface.
/// \throw TopologyError if it is neither.
/// \throw AlgorithmError if the solver fails, a triangle flips, or the distortion is extreme.
Parameterization parameterize(const TriMesh& input);

/// CGAL mean value coordinates of a disk, boundary fixed on the unit circle by arc length.
/// Returns one (u, v) row per vertex.
/// \pre disk is a topological disk without unreferenced vertices.
/// \throw AlgorithmError if CGAL reports a failure or returns non-finite coordinates.
Eigen::MatrixX2d mean_value_disk_map(const TriMesh& disk);

/// The Möbius transformation of the unit sphere that sends the point a (|a| < 1) of the ball
/// to its centre, applied to the unit vector x.
Eigen::Vector3d mobius_to_center(const Eigen::Vector3d& a, const Eigen::Vector3d& x);

}  // namespace mrsnake
