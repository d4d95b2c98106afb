#pragma once
/// \file quality.h
/// Triangle-mesh quality: angles, shape, edge lengths, areas and valence. The JSON keys of
/// QualityReport are those of `mrsnake quality --json` and are reused unchanged by every
/// report that has them (remesh, build-model, segment).
#include <nlohmann/json_fwd.hpp>

#include "mesh/trimesh.h"

namespace mrsnake {

/// Per-mesh quality figures. Angles in degrees, lengths in the mesh's units (mm).
struct QualityReport {
  int vertices = 0;
  int faces = 0;
  double min_angle_deg = 0;                            ///< smallest angle of any triangle
  double mean_min_angle_deg = 0;                       ///< mean over triangles of their smallest angle
  double pct_min_angle_below_30 = 0;                   ///< % of triangles whose smallest angle is < 30°
  double angle_deviation_deg = 0;                      ///< mean |θ − 60°| over all angles
  double angle_variance_deg2 = 0;                      ///< variance of all angles (the paper's Fig. 2)
  double q_min = 0, q_mean = 0;                        ///< Frey–Borouchaki Q = (6/√3)·A/(p·h); 1 = equilateral
  double radius_ratio_min = 0, radius_ratio_mean = 0;  ///< 2·r_in/r_circ; 1 = equilateral
  double edge_length_mean = 0;
  double edge_length_cv = 0;         ///< standard deviation / mean
  double edge_length_variance = 0;   ///< of lengths normalized by their mean (the paper's Fig. 2)
  double pct_valence6_interior = 0;  ///< % of interior vertices with valence 6
  double pct_valence4_boundary = 0;  ///< % of boundary vertices with valence 4 (0 if closed)
  double area_cv = 0;                ///< coefficient of variation of the triangle areas
};

/// Frey–Borouchaki quality of a triangle: (6/√3)·A/(p·h), p the half-perimeter, h the
/// longest edge. 1 for an equilateral triangle, 0 for a degenerate one.
double frey_borouchaki_quality(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// Radius ratio 2·r_in/r_circ of a triangle: 1 for equilateral, 0 for degenerate.
double radius_ratio(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// Computes every figure of QualityReport.
/// \pre the mesh has at least one face.
QualityReport mesh_quality(const TriMesh& mesh);

void to_json(nlohmann::json& j, const QualityReport& q);

}  // namespace mrsnake
