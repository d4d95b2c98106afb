#pragma once
/// \file lloyd.h
/// The paper's constrained Lloyd iteration (section 4.4). The neighbourhood N(v) of a vertex
/// is made, in each triangle (v, a, b) of its 1-ring, of the quadrilateral
/// (v, mid(v,a), barycenter(v,a,b), mid(v,b)): exactly the part of the triangle where v's
/// barycentric coordinate is the largest. N(v) tiles D, lies inside v's 1-ring, and its
/// density-weighted centroid is where v moves. The density is integrated per quadrilateral.
#include <array>
#include <vector>

#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

/// A density on D given per vertex of a DomainMesh and interpolated linearly.
struct DensityField {
  const DomainMesh* mesh = nullptr;
  Eigen::VectorXd vertex_density;  ///< > 0, one per vertex of *mesh
  /// Density at p, walking from `hint` (updated to the face found).
  double at(const Eigen::Vector3d& p, int& hint) const;
};

struct LloydOptions {
  int iterations = 8;
  int first_movable = 0;  ///< vertices [0, first_movable) stay fixed (the paper's strict mode)
  double step = 1.0;      ///< fraction of the way to the centroid moved per iteration
  /// Density samples per iteration over all faces: a face gets about budget / faces of them
  /// (at least the 3 corner-quadrilateral centroids, from about 2.8k faces up). Coarse levels
  /// integrate finely; at the fine levels 3 samples per face suffice, as the density is
  /// interpolated linearly from the input's vertices (docs/remesh.md, "Tuning knobs").
  int sample_budget = 25000;
};

struct LloydStats {
  int moves = 0;            ///< vertex moves made
  int shortened_moves = 0;  ///< moves shortened because the full move would flip a triangle
  int rejected_moves = 0;   ///< moves dropped for the same reason
  double mean_shift = 0;    ///< mean move of the last iteration (in D)
};

/// Relaxes the positions U (in D) of the triangulation F by constrained Lloyd iterations.
/// Boundary vertices (disk) stay on the unit circle. A move that would flip a triangle in D is
/// halved until it does not, so no triangle ever flips.
/// \pre no triangle of (U, F) is flipped; `vertex_hints` has one face hint per vertex.
LloydStats constrained_lloyd(DomainKind kind, const RowMatrixX3i& F, const DensityField& density, RowMatrixX3d& U,
                             std::vector<int>& vertex_hints, const LloydOptions& options);

/// N(v) as one quadrilateral (v, mid(v,a), barycenter, mid(v,b)) per incident face.
std::vector<std::array<Eigen::Vector3d, 4>> lloyd_cell(const RowMatrixX3i& F, const RowMatrixX3d& U, int v);

/// The centroid of N(v) under a constant density (flat triangles), before projection onto D.
Eigen::Vector3d lloyd_cell_centroid(const RowMatrixX3i& F, const RowMatrixX3d& U, int v);

}  // namespace mrsnake
