#pragma once
/// \file stretch_map.h
/// Distortion-minimizing maps onto D, built hierarchically as in Praun and Hoppe's spherical
/// parametrization (2003), with the MIPS energy plus an area term as the distortion.
///
/// A conformal map squeezes a protrusion's far end exponentially (a horse's hoof gets 1e-17 of
/// the sphere). The energy here grows without bound as a domain triangle shrinks or goes flat,
/// so minimizing it bounds that squeeze, and it is a barrier against flipped triangles. Built
/// coarse to fine, from a tetrahedron through the vertex splits of a progressive mesh, the map
/// never has to undo an exponential squeeze: each leg has its domain area from the level its
/// first vertices appear on. The price is anisotropy: a long tube cannot lie on a sphere both
/// conformally and with its own area.
#include "mesh/trimesh.h"
#include "remesh/domain.h"

namespace mrsnake {

/// Options of hierarchical_sphere_map().
struct HierarchicalMapOptions {
  /// λ of the area term: 0.003 bounds a protrusion's squeeze to a few orders of magnitude while
  /// the map stays as near conformal as the shape allows (on cactus, helix, horse, human and
  /// cheburashka, 0.001-0.01 gave the remesher's best triangles; pure area preservation, the
  /// symmetric Dirichlet energy, gave the worst).
  double area_weight = 0.003;
  /// Sweeps over all vertices at the end (or fewer, once a sweep lowers the energy by less
  /// than `tolerance`, relative).
  int final_sweeps = 12;
  double tolerance = 1e-3;
  /// Hierarchical map: sweeps over the vertices present each time their number has grown by
  /// `growth` since the last such round.
  int level_sweeps = 2;
  double growth = 1.5;
};

/// The minimized energy: Σ over faces of A3D (‖J‖²/det J + area_weight (det J + 1/det J)), J
/// the Jacobian of the affine map from the domain triangle (the chord triangle on the sphere)
/// to the surface triangle. The surface is taken as given (callers scale it to D's area).
/// Infinite when a face is flat or flipped in D.
/// \pre domain has one row per vertex of mesh.
double map_energy(const TriMesh& mesh, const RowMatrixX3d& domain, double area_weight);

/// Sander et al.'s normalized L2 stretch, sqrt(Σ A3D ½‖J‖² / ΣA3D · ΣA_D / ΣA3D): 1 for a map
/// that is a similarity on every face, larger otherwise.
double normalized_stretch(const TriMesh& mesh, const RowMatrixX3d& domain);

/// The hierarchical near-conformal map of a closed genus-0 surface onto the unit sphere:
/// half-edge collapses down to a tetrahedron, then the vertex splits in reverse, each new vertex
/// placed in its star's kernel and relaxed with its neighbours (map_energy, downhill vertex by
/// vertex, never through a flip), and all vertices relaxed each time their number grows by
/// HierarchicalMapOptions::growth.
/// \pre mesh is a closed genus-0 manifold without unreferenced vertices.
/// \throw AlgorithmError if the collapses cannot reach a tetrahedron or a split cannot be placed.
RowMatrixX3d hierarchical_sphere_map(const TriMesh& mesh, const HierarchicalMapOptions& options = {});

}  // namespace mrsnake
