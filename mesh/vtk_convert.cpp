#include "mesh/vtk_convert.h"

#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkTriangleFilter.h>

#include <algorithm>

namespace mrsnake {

TriMesh from_polydata(vtkPolyData* input) {
  vtkNew<vtkTriangleFilter> triangulate;
  triangulate->SetInputData(input);
  triangulate->PassVertsOff();
  triangulate->PassLinesOff();
  triangulate->Update();
  vtkPolyData* poly = triangulate->GetOutput();
  TriMesh mesh;
  mesh.V.resize(poly->GetNumberOfPoints(), 3);
  for (vtkIdType i = 0; i < poly->GetNumberOfPoints(); ++i) {
    double p[3];
    poly->GetPoint(i, p);
    mesh.V.row(i) << p[0], p[1], p[2];
  }
  vtkCellArray* polys = poly->GetPolys();
  mesh.F.resize(polys->GetNumberOfCells(), 3);
  vtkNew<vtkIdList> ids;
  polys->InitTraversal();
  for (int f = 0; polys->GetNextCell(ids); ++f)
    for (int k = 0; k < 3; ++k) mesh.F(f, k) = static_cast<int>(ids->GetId(k));
  return mesh;
}

vtkSmartPointer<vtkPolyData> to_polydata(const TriMesh& mesh) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(mesh.num_vertices());
  for (int i = 0; i < mesh.num_vertices(); ++i) points->SetPoint(i, mesh.V(i, 0), mesh.V(i, 1), mesh.V(i, 2));
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(mesh.num_faces(), 3 * mesh.num_faces());
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const vtkIdType ids[3] = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
    polys->InsertNextCell(3, ids);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(polys);
  return poly;
}

vtkSmartPointer<vtkImageData> to_index_space_image(const Volume& volume, int pad, float pad_value) {
  auto image = vtkSmartPointer<vtkImageData>::New();
  const int nx = static_cast<int>(volume.size[0]) + 2 * pad;
  const int ny = static_cast<int>(volume.size[1]) + 2 * pad;
  const int nz = static_cast<int>(volume.size[2]) + 2 * pad;
  image->SetDimensions(nx, ny, nz);
  image->SetOrigin(-pad, -pad, -pad);
  image->SetSpacing(1, 1, 1);
  vtkNew<vtkFloatArray> scalars;
  scalars->SetNumberOfTuples(static_cast<vtkIdType>(nx) * ny * nz);
  float* dst = scalars->GetPointer(0);
  std::fill(dst, dst + static_cast<std::size_t>(nx) * ny * nz, pad_value);
  for (std::size_t k = 0; k < volume.size[2]; ++k)
    for (std::size_t j = 0; j < volume.size[1]; ++j) {
      const float* src = &volume.data[volume.index(0, j, k)];
      float* row = dst + (pad + static_cast<std::size_t>(nx) * ((j + pad) + static_cast<std::size_t>(ny) * (k + pad)));
      std::copy(src, src + volume.size[0], row);
    }
  image->GetPointData()->SetScalars(scalars);
  return image;
}

}  // namespace mrsnake
