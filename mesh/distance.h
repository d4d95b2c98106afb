#pragma once
/// \file distance.h
/// Distances between surfaces and closest-point queries (CGAL AABB tree behind a small
/// adapter: no CGAL type crosses this header).
#include <memory>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "mesh/trimesh.h"

namespace mrsnake {

/// Closest points on a fixed triangle mesh. The tree is built once and reused.
class SurfaceLocator {
 public:
  struct Hit {
    Eigen::Vector3d point;        ///< closest point on the surface
    int face = -1;                ///< the face that holds it
    Eigen::Vector3d barycentric;  ///< its barycentric coordinates in that face
    double distance = 0;
  };
  /// \pre mesh has at least one face.
  explicit SurfaceLocator(const TriMesh& mesh);
  ~SurfaceLocator();
  SurfaceLocator(SurfaceLocator&&) noexcept;
  SurfaceLocator& operator=(SurfaceLocator&&) noexcept;

  Hit closest(const Eigen::Vector3d& p) const;
  /// Unsigned distance from each row of P to the surface.
  Eigen::VectorXd distances(const RowMatrixX3d& P) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Options for the Metro-style symmetric distance.
struct DistanceOptions {
  int samples_per_face = 10;  ///< random points per face, on top of every vertex
  unsigned seed = 1;          ///< for reproducible sampling
  /// > 0: at most this many points (vertices and face samples) of the mesh with more are
  /// measured, a uniform random subset, and the other mesh's points are thinned by the same
  /// fraction (same seed, same subsets): each direction keeps its weight, so the pooled RMS
  /// and mean stay unbiased; the Hausdorff distance is the largest over the subsets (a lower
  /// bound). 0 = all of them.
  long long max_samples_per_mesh = 0;
};

/// Symmetric surface distance: every vertex plus samples_per_face random points per face
/// of each mesh, measured against the other mesh, both directions pooled.
struct SurfaceDistance {
  double mean_mm = 0, rms_mm = 0, hausdorff_mm = 0;
  double mean_pct = 0, rms_pct = 0, hausdorff_pct = 0;  ///< in % of the reference's bbox diagonal
  double reference_diagonal_mm = 0;
};

/// \pre both meshes have at least one face.
/// \throw InputError if either mesh has no face.
SurfaceDistance surface_distance(const TriMesh& mesh, const TriMesh& reference, const DistanceOptions& options = {});

/// The same, with a locator already built on `reference`: several meshes measured against
/// one reference build its tree once.
/// \pre reference_locator was built on `reference`; both meshes have at least one face.
/// \throw InputError if either mesh has no face.
SurfaceDistance surface_distance(const TriMesh& mesh, const TriMesh& reference, const SurfaceLocator& reference_locator,
                                 const DistanceOptions& options = {});

/// Number of pairs of faces that intersect (not counting neighbours that only share a
/// vertex or an edge). 0 for a valid closed surface. Faces with a repeated corner are ignored.
/// \throw TopologyError if a face makes the mesh non-manifold or inconsistently oriented
///        (CGAL's halfedge mesh cannot hold it).
int count_self_intersections(const TriMesh& mesh);

/// The pairs of faces (indices into mesh.F, first < second) that share no vertex and
/// intersect: the surface passing through itself. Faster than self_intersecting_face_pairs
/// (boxes, then an exact triangle test on the non-adjacent overlaps only), but blind to
/// faces that share a vertex or an edge and overlap (a fold), which it leaves to the caller,
/// and to degenerate (zero-area) faces, which it skips.
/// \pre every index in mesh.F is a row of mesh.V.
std::vector<std::pair<int, int>> crossing_face_pairs(const TriMesh& mesh);

/// The pairs of faces (indices into mesh.F, first < second) that intersect, as
/// count_self_intersections counts them.
/// \throw TopologyError as count_self_intersections does.
std::vector<std::pair<int, int>> self_intersecting_face_pairs(const TriMesh& mesh);

void to_json(nlohmann::json& j, const SurfaceDistance& d);

}  // namespace mrsnake
