// CGAL adapter: mean value coordinates parameterization of a disk (the only CGAL
// parameterization translation unit).
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Simple_cartesian.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Surface_mesh_parameterization/Circular_border_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/Error_code.h>
#include <CGAL/Surface_mesh_parameterization/Mean_value_coordinates_parameterizer_3.h>
#include <CGAL/Surface_mesh_parameterization/parameterize.h>
#include <CGAL/Eigen_solver_traits.h>

#include <Eigen/KLUSupport>
#include <Eigen/SparseLU>

#include <cmath>
#include <memory>
#include <vector>

#include "mesh/errors.h"
#include "remesh/parameterization.h"

namespace mrsnake {
namespace {

using EigenMatrix = CGAL::Eigen_sparse_matrix<double>::EigenType;
// Only the types (Matrix, Vector, NT) of these traits are used: the solve is ours.
using BaseTraits = CGAL::Eigen_solver_traits<Eigen::SparseLU<EigenMatrix, Eigen::COLAMDOrdering<int>>>;

// CGAL solves the same matrix for u and for v: factor it once, with SuiteSparse's KLU. A mean
// value matrix is an M-matrix (an interior row's positive weights sum to its diagonal, a border
// row is the identity's), so the diagonal stays the pivot and the factorization is driven by the fill of KLU's AMD
// ordering of A + Aᵀ. On a 31k-vertex disk it takes 0.15 s, where Eigen's SparseLU with the same AMD ordering took 0.28
// s. KLU's block triangular form is off: a connected mesh's matrix is one irreducible block, and looking for the blocks
// costs time.
struct KLUTraits : BaseTraits {
  const Matrix* factored = nullptr;
  // Shared: CGAL copies the traits.
  std::shared_ptr<Eigen::KLU<EigenMatrix>> lu = std::make_shared<Eigen::KLU<EigenMatrix>>();
  bool linear_solver(const Matrix& A, const Vector& B, Vector& X, NT& D) {
    if (factored != &A) {
      lu->kluCommon().btf = 0;
      lu->compute(A.eigen_object());
      if (lu->info() != Eigen::Success) return false;
      factored = &A;
    }
    D = 1;
    const Eigen::VectorXd b = B;
    const Eigen::VectorXd x = lu->solve(b);
    if (lu->info() != Eigen::Success) return false;
    X = x;
    return true;
  }
};

}  // namespace

Eigen::MatrixX2d mean_value_disk_map(const TriMesh& disk) {
  using Kernel = CGAL::Simple_cartesian<double>;
  using Point_2 = Kernel::Point_2;
  using Point_3 = Kernel::Point_3;
  using SurfaceMesh = CGAL::Surface_mesh<Point_3>;
  using VertexIndex = SurfaceMesh::Vertex_index;
  namespace SMP = CGAL::Surface_mesh_parameterization;
  using Border = SMP::Circular_border_arc_length_parameterizer_3<SurfaceMesh>;
  using Parameterizer = SMP::Mean_value_coordinates_parameterizer_3<SurfaceMesh, Border, KLUTraits>;

  SurfaceMesh sm;
  std::vector<VertexIndex> vertex(disk.num_vertices());
  for (int v = 0; v < disk.num_vertices(); ++v)
    vertex[v] = sm.add_vertex(Point_3(disk.V(v, 0), disk.V(v, 1), disk.V(v, 2)));
  for (int f = 0; f < disk.num_faces(); ++f) {
    const auto face = sm.add_face(vertex[disk.F(f, 0)], vertex[disk.F(f, 1)], vertex[disk.F(f, 2)]);
    if (face == SurfaceMesh::null_face())
      throw AlgorithmError("the surface could not be built for parameterization (face " + std::to_string(f) +
                           " is non-manifold); repair the mesh first");
  }
  const auto border = CGAL::Polygon_mesh_processing::longest_border(sm).first;
  if (border == SurfaceMesh::null_halfedge()) throw AlgorithmError("the surface to parameterize has no boundary");
  auto uv = sm.add_property_map<VertexIndex, Point_2>("v:uv").first;
  const SMP::Error_code err = SMP::parameterize(sm, Parameterizer(), border, uv);
  if (err != SMP::OK)
    throw AlgorithmError(std::string("the parameterization failed (CGAL: ") + SMP::get_error_message(err) +
                         "); the surface may have degenerate triangles: repair or smooth it first");
  Eigen::MatrixX2d out(disk.num_vertices(), 2);
  for (int v = 0; v < disk.num_vertices(); ++v) {
    const Point_2& p = uv[vertex[v]];
    out(v, 0) = p.x();
    out(v, 1) = p.y();
    if (!std::isfinite(out(v, 0)) || !std::isfinite(out(v, 1)))
      throw AlgorithmError(
          "the parameterization produced non-finite coordinates; the surface may have degenerate "
          "triangles: repair or smooth it first");
  }
  return out;
}

}  // namespace mrsnake
