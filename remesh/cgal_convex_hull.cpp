// CGAL adapter: 3D convex hull.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

#include <algorithm>
#include <array>
#include <map>
#include <tuple>
#include <vector>

#include "mesh/errors.h"
#include "remesh/convex_hull.h"

namespace mrsnake {

RowMatrixX3i convex_hull_faces(const RowMatrixX3d& points) {
  using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
  using Point_3 = Kernel::Point_3;
  using SurfaceMesh = CGAL::Surface_mesh<Point_3>;
  std::vector<Point_3> pts;
  std::map<std::tuple<double, double, double>, int> index;
  for (int i = 0; i < points.rows(); ++i) {
    pts.emplace_back(points(i, 0), points(i, 1), points(i, 2));
    index.emplace(std::make_tuple(points(i, 0), points(i, 1), points(i, 2)), i);
  }
  SurfaceMesh hull;
  CGAL::convex_hull_3(pts.begin(), pts.end(), hull);
  if (hull.number_of_faces() < 4) throw AlgorithmError("the base mesh is degenerate (its points are coplanar)");
  std::vector<std::array<int, 3>> faces;
  faces.reserve(hull.number_of_faces());
  for (const auto f : hull.faces()) {
    std::array<int, 3> face{};
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) {
      if (k == 3) throw AlgorithmError("the convex hull of the base points has a non-triangular face");
      const Point_3& p = hull.point(v);
      face[k++] = index.at(std::make_tuple(p.x(), p.y(), p.z()));
    }
    // Smallest index first (orientation kept).
    std::rotate(face.begin(), std::min_element(face.begin(), face.end()), face.end());
    faces.push_back(face);
  }
  // CGAL's face order follows its internal (address-dependent) bookkeeping, so it can change
  // from call to call in one process: sorted, the same points always give the same faces.
  std::sort(faces.begin(), faces.end());
  RowMatrixX3i F(static_cast<int>(faces.size()), 3);
  for (std::size_t i = 0; i < faces.size(); ++i)
    for (int k = 0; k < 3; ++k) F(static_cast<int>(i), k) = faces[i][k];
  return F;
}

}  // namespace mrsnake
