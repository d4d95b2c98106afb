#include "mesh/merge.h"

namespace mrsnake {

TriMesh merged_meshes(const std::vector<const TriMesh*>& meshes) {
  Eigen::Index nv = 0, nf = 0;
  for (const TriMesh* m : meshes) {
    nv += m->num_vertices();
    nf += m->num_faces();
  }
  TriMesh all;
  all.V.resize(nv, 3);
  all.F.resize(nf, 3);
  Eigen::Index v = 0, f = 0;
  for (const TriMesh* m : meshes) {
    all.V.middleRows(v, m->num_vertices()) = m->V;
    all.F.middleRows(f, m->num_faces()) = m->F.array() + static_cast<int>(v);
    v += m->num_vertices();
    f += m->num_faces();
  }
  return all;
}

}  // namespace mrsnake
