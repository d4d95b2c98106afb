#pragma once
/// \file base_lift.h
/// The inverse of the parameterization onto the base-mesh domain: a point of D -> the input
/// surface. Each input triangle is a straight triangle in one chart, the common chart of its
/// three corners' locations; a point is found in the charts that hold it.
///
/// Charts agree on each face of K up to an affine map, so triangles inside one face of K tile
/// D exactly. A triangle across an edge of K is straight in its own chart only (that of the K
/// vertex nearest to it): where neighbours across the edge chose the charts of its two ends
/// (near its midpoint), they leave narrow gaps and overlaps, about the triangle's size times the
/// difference of the two charts' Jacobians (some 8% of an input edge on an icosahedron). A
/// point in a gap gets the nearest triangle tried.
#include <vector>

#include "mesh/trimesh.h"
#include "remesh/base_domain.h"

namespace mrsnake {

class BaseLift {
 public:
  /// A face of the input and barycentric coordinates in it (its corner order, >= 0, sum 1).
  struct Hit {
    int face = -1;
    Eigen::Vector3d bary = Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);
  };

  /// Places every input triangle in the common chart of its corners' locations and indexes
  /// each chart's triangles in a uniform grid. Triangles with no common chart, or degenerate in
  /// theirs, are skipped and counted (unmapped_triangles).
  /// \pre location has one entry per input vertex, each a point of domain; the input's triangles
  ///      are small relative to K's, so that each one's locations share a chart. domain outlives
  ///      this object.
  /// \throw std::invalid_argument if location has the wrong size.
  BaseLift(const TriMesh& input, const BaseDomain& domain, std::vector<BasePoint> location);

  /// The input triangle holding p in a chart that holds p (barycentric coordinates >= -1e-9,
  /// then clamped), searched in the charts of p's face's corners first. In a gap between
  /// triangles (skipped ones, or charts that disagree across an edge of K), the nearest of the
  /// triangles tried, with its coordinates clamped.
  /// \pre p is a point of the domain.
  /// \throw AlgorithmError if no input triangle is mapped in any chart holding p.
  Hit locate(const BasePoint& p) const;

  /// The point of the input surface at p: locate(p)'s face at its barycentric coordinates.
  /// \pre as locate. \throw as locate.
  Eigen::Vector3d lift(const BasePoint& p) const;

  const RowMatrixX3d& input_vertices() const { return V_; }
  const RowMatrixX3i& input_faces() const { return F_; }
  /// Input vertex i's point of D.
  const BasePoint& location(int i) const { return location_[i]; }

  /// Input triangles not placed in any chart (no common chart, or degenerate in it).
  int unmapped_triangles() const { return unmapped_; }

 private:
  /// An input triangle in a chart: its barycentric coordinates (b1, b2) at q are
  /// inverse · (q − origin), origin its first corner.
  struct ChartTriangle {
    int face;
    Eigen::Vector2d origin;
    Eigen::Matrix2d inverse;
  };
  /// A chart's triangles binned by bounding box: cell (x, y) lists entries
  /// offset[y·nx + x] … offset[y·nx + x + 1] − 1 of `items` (indices into triangles_).
  struct Grid {
    Eigen::Vector2d low = Eigen::Vector2d::Zero(), inverse_cell = Eigen::Vector2d::Zero();
    int nx = 0, ny = 0;
    std::vector<int> offset, items;
  };
  /// The best triangle of chart v for q (the largest smallest coordinate) if it beats
  /// best_min; updates hit and best_min. `all`: every triangle of the chart, not q's cell.
  void search_chart(int v, const Eigen::Vector2d& q, bool all, Hit& hit, double& best_min) const;
  void build_grid(int v, const std::vector<Eigen::Matrix<double, 2, 3>>& corners);

  RowMatrixX3d V_;
  RowMatrixX3i F_;
  const BaseDomain* domain_;
  std::vector<BasePoint> location_;
  /// The triangles of chart v: triangles_[chart_offset_[v] … chart_offset_[v + 1]).
  std::vector<ChartTriangle> triangles_;
  std::vector<int> chart_offset_;
  std::vector<Grid> grid_;
  int unmapped_ = 0;
};

}  // namespace mrsnake
