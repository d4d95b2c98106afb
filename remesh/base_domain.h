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
#include <boost/container/small_vector.hpp>

#include "mesh/trimesh.h"

namespace mrsnake {

/// A point of D: a face of K and barycentric coordinates in it (in its corner order, >= 0,
/// sum 1). A point on an edge or a vertex of K may be named by any face that holds it.
struct BasePoint {
  int face = -1;
  Eigen::Vector3d bary = Eigen::Vector3d(1.0 / 3, 1.0 / 3, 1.0 / 3);
};

/// The widest wedge of a vertex chart (radians), well short of π where it would fold.
constexpr double kWidestWedge = 0.75 * 3.14159265358979323846;

/// The conformal flattening of a vertex star (MAPS, section 3.2): the ring vertices r_0..r_{k-1}
/// (in counter-clockwise order seen from outside) around a centre c go to
/// ρ·(|r_i - c|/ρ)^a · (cos(a·φ_i), sin(a·φ_i)), ρ the mean of the |r_i - c|, with φ_i the sum
/// of the 3D angles at c of the triangles (c, r_0, r_1) … (c, r_{i-1}, r_i), and
/// a = 2π / (the total angle) for an interior vertex (`closed`: the ring closes, r_{k-1} -> r_0
/// is a triangle too), π / (the total angle) on a boundary (the ring runs from one boundary
/// neighbour to the other).
/// Where a scaled wedge would exceed kWidestWedge (it folds at π: a sharp tip with one wide
/// angle), the wedges are blended toward equal ones just enough that none does.
/// \pre ring has at least 3 vertices (2 on a boundary), none at c.
std::vector<Eigen::Vector2d> flatten_star(const Eigen::Vector3d& center, const std::vector<Eigen::Vector3d>& ring,
                                          bool closed);

/// The base mesh K as the domain, with one chart per vertex (flatten_star of its ring, v at
/// the origin, each star face a straight triangle). A boundary vertex with a single face keeps
/// that face's own shape: spanning π would flatten it to a segment.
class BaseDomain {
 public:
  /// The charts holding a point: a face's 3 corners, or the ring of an edge or a vertex of K.
  /// Held inline up to 16: a point is located millions of times, and a heap list each time
  /// cost about 3 % of a base-mesh remeshing.
  using ChartList = boost::container::small_vector<int, 16>;

  /// Precomputes every vertex's ordered star and its faces' corners in the vertex's chart.
  /// \pre base is a closed genus-0 manifold or a disk, consistently oriented, no unreferenced
  ///      vertices, no vertex at a neighbour's position.
  /// \throw TopologyError if a vertex's faces are not a single fan (non-manifold), or none.
  explicit BaseDomain(TriMesh base);

  const TriMesh& base() const { return base_; }

  /// The 3D point of p on K: its face's corners weighted by p.bary.
  /// \pre p.face is a face of K.
  /// \throw nothing.
  Eigen::Vector3d position(const BasePoint& p) const;

  /// K's vertex v as a point: the first face of its star, with unit weight on v.
  /// \pre v is a vertex of K.
  /// \throw nothing.
  BasePoint vertex_point(int v) const;

  /// Whether v's star holds p: p's face is in the star, or the corners of p's face that carry
  /// weight (bary > kOnSimplex) are corners of one face of the star (p on a shared edge or vertex).
  /// \pre v is a vertex of K, p a point of D.
  /// \throw nothing.
  bool in_star(int v, const BasePoint& p) const;

  /// The K vertices whose star holds p (in_star): p's face's corners, and, for p on an edge or a
  /// vertex of K, the corners of the other faces around it.
  /// \pre p is a point of D.
  /// \throw nothing beyond std::bad_alloc.
  ChartList charts_holding(const BasePoint& p) const;

  /// p's position in v's chart. A point named by a face outside the star, but lying on an
  /// edge or vertex the star shares, is placed by the star face that holds it.
  /// \pre in_star(v, p).
  /// \throw std::invalid_argument if p is not in v's star.
  Eigen::Vector2d to_chart(int v, const BasePoint& p) const;

  /// p's position in v's chart (as to_chart), or nullopt where v's star does not hold p: one
  /// search of the star where in_star() then to_chart() make two.
  /// \pre v is a vertex of K, p a point of D.
  /// \throw nothing.
  std::optional<Eigen::Vector2d> chart_point(int v, const BasePoint& p) const;

  /// The point at q in v's chart: the star face holding q (barycentric coordinates >=
  /// -kChartSlack, clamped to >= 0 and renormalized; the most inside face when q is on an
  /// edge), or nullopt if q is outside the star.
  /// \pre v is a vertex of K.
  /// \throw nothing.
  std::optional<BasePoint> from_chart(int v, const Eigen::Vector2d& q) const;

  /// A K vertex whose star holds all `count` points, or -1 if none does. Of several, the one
  /// whose star holds them deepest (the largest sum of depth()), then the one nearest in 3D to
  /// the points' centroid: its chart is the least distorted around them.
  /// \pre count >= 1; points[0 … count) are points of D.
  /// \throw nothing beyond std::bad_alloc.
  int common_chart(const BasePoint* points, int count) const;

  /// p's weight on v in the star face of v that holds it: 1 at v, 0 on the star's rim; -1 if
  /// the star does not hold p.
  /// \pre v is a vertex of K, p a point of D.
  double depth(int v, const BasePoint& p) const;

  /// The 2D cross product of (b − a, c − a) in the common chart of the three points (> 0 when
  /// a, b, c run counter-clockwise seen from outside), NaN when they have none.
  /// \pre a, b, c are points of D.
  /// \throw nothing beyond std::bad_alloc.
  double orientation(const BasePoint& a, const BasePoint& b, const BasePoint& c) const;

  /// Whether some chart that holds a, b and c sees them counter-clockwise. Charts agree on the
  /// orientation of a triangle inside one face of K (they differ there by an affine map that
  /// keeps it); across an edge or a vertex of K, where they kink, a triangle small enough to be
  /// nearly degenerate may be counter-clockwise in one and not in another, and it is not folded
  /// while one chart holds it unfolded. A folded triangle is clockwise in all of them.
  /// \pre a, b, c are points of D.
  /// \throw nothing beyond std::bad_alloc.
  bool counter_clockwise(const BasePoint& a, const BasePoint& b, const BasePoint& c) const;

  /// Barycentric coordinates at most this are treated as 0 when deciding which simplex of K
  /// holds a point (in_star).
  static constexpr double kOnSimplex = 1e-12;
  /// How far below 0 a barycentric coordinate may be for from_chart to accept a point.
  static constexpr double kChartSlack = 1e-9;

 private:
  /// The index in the star arrays of the face of v's star holding p, and p's barycentric
  /// coordinates in that face (its corner order); -1 if v's star does not hold p.
  int star_slot(int v, const BasePoint& p, Eigen::Vector3d& bary) const;

  TriMesh base_;
  /// Vertex v's star, counter-clockwise from outside (from one boundary neighbour to the other
  /// on a boundary): entries star_offset_[v] … star_offset_[v + 1] − 1 of the arrays below.
  std::vector<int> star_offset_, star_face_;
  /// Per star entry, the chart positions of the face's corners (column k: corner k of the face).
  std::vector<Eigen::Matrix<double, 2, 3>> star_corners_;
  /// slot_(f, k): the star entry of face f in the star of its corner k.
  RowMatrixX3i slot_;
};

}  // namespace mrsnake
