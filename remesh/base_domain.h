#pragma once
/// \file base_domain.h
/// The base mesh K as the parameter domain D (MAPS, the seed paper's refs [5, 9]): a point of D
/// is a face of K and barycentric coordinates in it. D follows the shape, so a protrusion keeps
/// a domain area in proportion to its own, which no single map onto the sphere can give.
///
/// Every vertex v of K has a chart: its star flattened by the conformal map z^a of MAPS (v at
/// the origin, the ring's angles scaled to sum 2π, or π on a boundary; radii raised to the
/// power a), each face of the star a straight triangle in the chart. A chart is piecewise
/// linear on the faces it holds, so a point has the same chart position whichever of its
/// faces names it. Charts of different vertices do not agree, and need not: moves, midpoints
/// and orientation tests of a few nearby points are computed in one chart that holds them all.
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "mesh/trimesh.h"

namespace mrsnake {

/// A point of D: a face of K and barycentric coordinates in it (in its corner order, >= 0,
/// sum 1). A point on an edge or a vertex of K may be named by any face that holds it.
struct BasePoint {
  int face = -1;
  Eigen::Vector3d bary = Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);
};

/// The conformal flattening of a vertex star (MAPS, section 3.2): the ring vertices r_0..r_{k-1}
/// (in counter-clockwise order seen from outside) around a centre c go to
/// ρ·(|r_i - c|/ρ)^a · (cos(a·φ_i), sin(a·φ_i)), ρ the mean of the |r_i - c|, with φ_i the sum of the 3D angles at c of
/// the triangles (c, r_0, r_1) … (c, r_{i-1}, r_i), and a = 2π / (the total angle) for an interior vertex (`closed`:
/// the ring closes, r_{k-1} -> r_0 is a triangle too), π / (the total angle) on a boundary (the ring runs from one
/// boundary neighbour to the other). \pre ring has at least 3 vertices (2 on a boundary), none at c.
std::vector<Eigen::Vector2d> flatten_star(const Eigen::Vector3d& center, const std::vector<Eigen::Vector3d>& ring,
                                          bool closed);

}  // namespace mrsnake
