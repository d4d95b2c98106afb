#include "wavelets/local_frame.h"

#include <Eigen/Geometry>
#include <cmath>

namespace mrsnake {

LocalFrame parent_edge_frame(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& area_normal,
                             double reference_length, double tolerance) {
  LocalFrame frame;
  const Eigen::Vector3d edge = b - a;
  const double length = edge.norm();
  if (!std::isfinite(length) || !(length > tolerance * reference_length) || length == 0.0) {
    frame.degenerate = true;
    frame.scale = (std::isfinite(reference_length) && reference_length > 0.0) ? reference_length : 1.0;
    return frame;  // identity axes
  }
  const Eigen::Vector3d tangent = edge / length;
  Eigen::Vector3d normal = area_normal - area_normal.dot(tangent) * tangent;
  const double normal_length = normal.norm();
  if (std::isfinite(normal_length) && normal_length > tolerance * length * length) {
    normal /= normal_length;
  } else {
    // The coordinate axis least aligned with the tangent, made orthogonal to it.
    int axis = 0;
    tangent.cwiseAbs().minCoeff(&axis);
    normal = Eigen::Vector3d::Unit(axis) - tangent[axis] * tangent;
    normal.normalize();
    frame.degenerate = true;
  }
  frame.axes.col(0) = tangent;
  frame.axes.col(1) = normal.cross(tangent);
  frame.axes.col(2) = normal;
  frame.scale = length;
  return frame;
}

}  // namespace mrsnake
