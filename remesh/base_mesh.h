#pragma once
/// \file base_mesh.h
/// The base mesh T0 in D: base vertices spread evenly over the surface in 3D (farthest point
/// sampling), so that protrusions get their own base vertices, triangulated in D by Delaunay
/// (the convex hull on the sphere, the lifted lower hull in the disk), then, on a closed surface,
/// edge flips toward the surface's Delaunay triangulation, and edge flips that bring valences
/// toward 6 (4 on the boundary).
#include <functional>
#include <vector>

#include "mesh/trimesh.h"
#include "remesh/parameterization.h"

namespace mrsnake {

struct BaseMesh {
  RowMatrixX3i faces;           ///< F0, counter-clockwise in D
  RowMatrixX3d domain;          ///< n0 rows: base vertex positions in D
  std::vector<int> samples;     ///< the vertex of the parameterized surface under each base vertex
  int surface_flips = 0;        ///< edge flips made toward the surface's Delaunay triangulation
  int valence_flips = 0;        ///< edge flips made to even out valences
  int dropped_rim_samples = 0;  ///< disk rim samples dropped: fewer than rim_min_triangles triangles
};

/// One-chart sphere maps (punctured, two halves): a base edge is flipped toward the surface's
/// Delaunay triangulation where its two facing angles on the surface sum to more than 180° plus
/// this margin, in degrees. The sphere's Delaunay triangulation is the surface's where the map
/// is conformal; where it stretches (a cactus's arms), its base triangles are long in 3D.
/// Edges only just past 180° are left as the sphere made them (docs/remesh.md measures 0 to
/// 30 on the bench's inputs).
inline constexpr double kOneChartFlipMarginDeg = 15.0;

/// With a disk, rim samples left with fewer than rim_min_triangles triangles are dropped and
/// the rest triangulated again (up to 4 times), so the result may have fewer than n0 vertices.
/// With `density` (a wanted point density per vertex of param.surface, > 0) the interior
/// samples are spaced ∝ density^(-1/2) instead of evenly, so more base vertices (and their
/// irregular valences) sit where the surface bends.
/// A closed surface's base is flipped toward the surface's Delaunay triangulation before the
/// valence flips: every edge the hierarchical map leaves past 180°, and, on a one-chart map,
/// those past 180° + one_chart_flip_margin_deg (>= 180: none) whose ends keep five edges.
/// \pre param comes from parameterize(); n0 >= 6; density, if given, has one entry per vertex;
/// one_chart_flip_margin_deg >= 0.
/// \throw AlgorithmError if no valid base triangulation results.
BaseMesh build_base_mesh(const Parameterization& param, int n0, int rim_min_triangles = 3,
                         const Eigen::VectorXd* density = nullptr,
                         double one_chart_flip_margin_deg = kOneChartFlipMarginDeg);

/// An interior edge a-b of the faces f1 = (a, b, c) and f2 = (b, a, d) (up to rotation) that
/// a flip turns into c-d, making f1 = (a, d, c) and f2 = (d, b, c).
struct EdgeFlip {
  int f1, f2, a, b, c, d;
};

/// Whether a flip may be made. It is asked just before the faces change, so it may also update
/// what hangs on them (the points located in them, for the base-mesh domain).
using FlipGuard = std::function<bool(const EdgeFlip&)>;

/// Which edges flip_toward_surface_delaunay() flips.
struct SurfaceFlipOptions {
  /// Radians by which the two angles facing an edge on the surface must sum past pi.
  double margin = 0;
  /// Edges that each end of a flipped edge keeps, at least.
  int min_end_edges = 3;
};

/// Flips interior edges whose two opposite angles on the surface (the vertices' 3D positions
/// X) sum to more than pi + options.margin, where `allowed` lets it and both ends keep
/// options.min_end_edges edges: the Delaunay triangulation of the vertices on the surface, as
/// far as the domain allows. Needed where the map is not conformal: a Delaunay triangulation in
/// D is then a poor one on the surface.
/// \pre options.margin >= 0, options.min_end_edges >= 3.
/// \return the number of flips made.
int flip_toward_surface_delaunay(const RowMatrixX3d& X, RowMatrixX3i& F, const FlipGuard& allowed,
                                 const SurfaceFlipOptions& options = {});

/// The same with the quad required convex in D (so that neither new face flips in D).
int flip_toward_surface_delaunay(const RowMatrixX3d& D, const RowMatrixX3d& X, RowMatrixX3i& F,
                                 const SurfaceFlipOptions& options = {});

/// Flips edges (never boundary edges, never making a duplicate edge, never leaving an interior
/// vertex with valence < 4, whose triangles' quality would be capped at every level, or a
/// boundary vertex with fewer than rim_min_triangles triangles)
/// where `allowed` lets it, while that lowers sum (valence - 6)² (boundary: 3·(valence - 4)²).
/// \return the number of flips made.
int flip_toward_regular_valence(int vertices, RowMatrixX3i& F, int rim_min_triangles, const FlipGuard& allowed);

/// The same with the quad required convex in D (so that neither new face flips in D).
int flip_toward_regular_valence(const RowMatrixX3d& D, RowMatrixX3i& F, int rim_min_triangles = 3);

}  // namespace mrsnake
