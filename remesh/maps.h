#pragma once
/// \file maps.h
/// The MAPS simplification (Lee, Sweldens, Schröder, Cowsar, Dobkin 1998, section 3): the input
/// is simplified to a base mesh K by removing vertices in rounds, each round an independent
/// set taken in priority order (small, flat stars first). A removed vertex's star is flattened
/// by the conformal map z^a (flatten_star), the hole retriangulated in that chart (the
/// triangulation of the evenest triangles that repeats no edge of K and turns no triangle
/// against the faces it covers), and every input vertex located in the old star is located
/// again in the new triangles from its chart position. At the end every input vertex has its
/// point of D = K (base_domain.h), and the map follows the shape: a protrusion keeps base faces
/// of its own. A disk loses rim vertices only where the rim stays close to the input's rim.
#include <vector>

#include "mesh/trimesh.h"
#include "remesh/base_domain.h"

namespace mrsnake {

struct MapsOptions {
  int base_vertices = 200;  ///< stop when K has at most this many vertices (at least 4)
  /// Removal priority: lambda·area/max_area + (1-lambda)·curvature/max_curvature, as MAPS.
  double curvature_weight = 0.5;
  int max_valence = 12;  ///< vertices of K with more neighbours are kept (their hole would be poor)
  /// Degrees: a rim vertex is kept if, without it, an input rim vertex on its two rim edges
  /// would lie farther from the new rim edge than a corner turning this much would (tan(turn/2)/2
  /// of the edge), beyond 0.6 of the input's mean rim edge (which lets a jagged rim be smoothed).
  double max_rim_turn = 30.0;
  /// A removal may not put an input vertex's point on K farther from it (in 3D) than this many
  /// times the longest edge of its new face: a guard against a chart that drags points away.
  double max_drift = 1.0;
  std::vector<int> feature_vertices;  ///< input vertices that stay in K (MAPS' feature vertices)
};

struct MapsParameterization {
  /// K: V = the input positions of its vertices, F counter-clockwise outward like the input.
  TriMesh base;
  std::vector<int> base_vertex;     ///< K vertex -> input vertex index
  std::vector<BasePoint> location;  ///< per input vertex: its point of D (a face of K and barycentric coordinates)
  /// Removals made and refused; a refusal counts once per attempt (a vertex may be tried each round).
  int removed_vertices = 0, refused_removals = 0;
  int rounds = 0;           ///< independent sets removed
  int refused_valence = 0;  ///< refused: the vertex has too many neighbours, or a neighbour would keep too few faces
  int refused_edge = 0;     ///< refused: every fill of the hole would repeat an edge of K (the link condition)
  int refused_fold = 0;     ///< refused: the chart folds, or every fill turns a triangle against the old faces in 3D
  int refused_rim = 0;      ///< refused: a rim vertex the rim's shape needs (max_rim_turn)
  int refused_drift = 0;    ///< refused: an input vertex would land too far from itself (max_drift)
};

/// Simplifies `input` to options.base_vertices vertices (or fewer, down to 4) and locates
/// every input vertex on the result; a vertex of K is located at its own corner (a unit
/// barycentric vector). If the removals stall above the target but within twice it, returns
/// that larger K. Deterministic.
/// \pre input is a closed genus-0 manifold or a disk, without unreferenced vertices, consistently oriented.
/// \throw TopologyError if the input is not such a mesh.
/// \throw AlgorithmError if it cannot be simplified to twice the target without breaking the map.
MapsParameterization maps_parameterize(const TriMesh& input, const MapsOptions& options = {});

}  // namespace mrsnake
