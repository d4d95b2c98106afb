#pragma once
/// \file local_frame.h
/// The local frame a detail vector is stored in. Each new vertex of level j+1 gets a frame
/// built only from the coarse level j (the positions synthesis has), so that analysis and
/// synthesis compute bit-identical frames, and a similarity applied to level j (rotation,
/// translation, uniform scale) moves the rebuilt finer levels with it.
#include <Eigen/Core>

namespace mrsnake {

/// An orthonormal frame and a length. A global detail d is stored as
/// axesᵀ·d / scale and rebuilt as scale·axes·d_local.
struct LocalFrame {
  /// Columns: tangent (along the parent edge, from its first to its second vertex),
  /// bitangent (normal × tangent) and normal (of the coarse faces around the parent edge).
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  double scale = 1.0;       ///< the parent edge length on the coarse level
  bool degenerate = false;  ///< true when the fallback below was used
};

/// The frame of a new vertex whose parent edge runs from a to b on the coarse level.
///
/// `area_normal` is the sum of the cross products (q1−q0)×(q2−q0) of the one or two coarse
/// faces that hold the edge. `reference_length` is the mean edge length of the coarse level
/// and `tolerance` the relative threshold of degeneracy. Fallbacks, in order:
/// - parent edge shorter than tolerance·reference_length (or not finite): axes = identity
///   (the global frame) and scale = reference_length (1 if that is not positive and finite);
/// - normal: the part of area_normal orthogonal to the tangent is no longer than
///   tolerance·|b−a|²: the normal becomes the coordinate axis least aligned with the tangent,
///   made orthogonal to it; scale stays |b−a|.
/// Both set `degenerate`. Either way the axes are orthonormal and right-handed.
LocalFrame parent_edge_frame(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& area_normal,
                             double reference_length, double tolerance);

/// Global → local: axesᵀ·d / scale.
inline Eigen::Vector3d to_local(const LocalFrame& f, const Eigen::Vector3d& d) {
  return f.axes.transpose() * d / f.scale;
}
/// Local → global: scale·axes·d_local.
inline Eigen::Vector3d to_global(const LocalFrame& f, const Eigen::Vector3d& d_local) {
  return f.scale * (f.axes * d_local);
}

}  // namespace mrsnake
