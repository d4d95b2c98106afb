// CGAL adapter: 3D convex hull.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/convex_hull_3.h>

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
  RowMatrixX3i F(static_cast<int>(hull.number_of_faces()), 3);
  int row = 0;
  for (const auto f : hull.faces()) {
    int k = 0;
    for (const auto v : CGAL::vertices_around_face(hull.halfedge(f), hull)) {
      if (k == 3) throw AlgorithmError("the convex hull of the base points has a non-triangular face");
      const Point_3& p = hull.point(v);
      F(row, k++) = index.at(std::make_tuple(p.x(), p.y(), p.z()));
    }
    ++row;
  }
  return F;
}

}  // namespace mrsnake
