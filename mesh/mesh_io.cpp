#include "mesh/mesh_io.h"

#include <vtkCellArray.h>
#include <vtkCleanPolyData.h>
#include <vtkNew.h>
#include <vtkOBJWriter.h>
#include <vtkPLYWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataWriter.h>
#include <vtkSTLWriter.h>
#include <vtkSmartPointer.h>
#include <vtkTriangleFilter.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "mesh/atomic_file.h"
#include "mesh/errors.h"
#include "mesh/legacy_vtk_reader.h"
#include "mesh/obj_reader.h"
#include "mesh/ply_reader.h"
#include "mesh/stl_reader.h"
#include "mesh/vtk_convert.h"

namespace mrsnake {
namespace {

void validate(const TriMesh& mesh, const std::string& path) {
  if (mesh.num_faces() == 0) throw InputError("mesh '" + path + "' has no triangles");
  if (!mesh.V.allFinite())
    throw InputError("mesh '" + path + "' has NaN or infinite vertex coordinates; repair it first");
  if (mesh.F.minCoeff() < 0 || mesh.F.maxCoeff() >= mesh.num_vertices())
    throw InputError("mesh '" + path + "' has a face that references a missing vertex; the file is corrupt");
}

// OFF has no VTK reader: a small, strict parser (comments, optional colour columns).
TriMesh read_off(const std::string& path) {
  std::ifstream in(path);
  std::string token;
  auto next_line = [&](std::string& line) {
    while (std::getline(in, line)) {
      const auto hash = line.find('#');
      if (hash != std::string::npos) line.erase(hash);
      if (line.find_first_not_of(" \t\r") != std::string::npos) return true;
    }
    return false;
  };
  std::string line;
  if (!next_line(line)) throw InputError("mesh '" + path + "' is empty");
  std::istringstream header(line);
  header >> token;
  if (token.size() < 3 || token.substr(token.size() - 3) != "OFF")
    throw InputError("'" + path + "' is not an OFF file (no OFF header)");
  long nv = -1, nf = -1, ne = 0;
  if (!(header >> nv)) {
    if (!next_line(line)) throw InputError("OFF file '" + path + "' is truncated");
    std::istringstream counts(line);
    counts >> nv >> nf >> ne;
  } else {
    header >> nf >> ne;
  }
  if (nv <= 0 || nf <= 0 || nv > 100000000 || nf > 200000000)
    throw InputError("OFF file '" + path + "' has invalid vertex/face counts");
  TriMesh mesh;
  mesh.V.resize(nv, 3);
  for (long i = 0; i < nv; ++i) {
    if (!next_line(line)) throw InputError("OFF file '" + path + "' is truncated in its vertices");
    std::istringstream s(line);
    if (!(s >> mesh.V(i, 0) >> mesh.V(i, 1) >> mesh.V(i, 2)))
      throw InputError("OFF file '" + path + "' has a malformed vertex line " + std::to_string(i));
  }
  std::vector<Eigen::RowVector3i> tris;
  tris.reserve(nf);
  for (long f = 0; f < nf; ++f) {
    if (!next_line(line)) throw InputError("OFF file '" + path + "' is truncated in its faces");
    std::istringstream s(line);
    long k = 0;
    if (!(s >> k) || k < 3 || k > 10000)
      throw InputError("OFF file '" + path + "' has a malformed face " + std::to_string(f));
    std::vector<int> poly(k);
    for (long c = 0; c < k; ++c)
      if (!(s >> poly[c])) throw InputError("OFF file '" + path + "' has a malformed face " + std::to_string(f));
    for (long c = 1; c + 1 < k; ++c) tris.emplace_back(poly[0], poly[c], poly[c + 1]);  // fan
  }
  mesh.F.resize(static_cast<Eigen::Index>(tris.size()), 3);
  for (std::size_t f = 0; f < tris.size(); ++f) mesh.F.row(static_cast<Eigen::Index>(f)) = tris[f];
  return mesh;
}

void write_off(const std::string& path, const TriMesh& mesh) {
  std::ofstream out(path);
  out.precision(17);
  out << "OFF\n" << mesh.num_vertices() << ' ' << mesh.num_faces() << " 0\n";
  for (int i = 0; i < mesh.num_vertices(); ++i)
    out << mesh.V(i, 0) << ' ' << mesh.V(i, 1) << ' ' << mesh.V(i, 2) << '\n';
  for (int f = 0; f < mesh.num_faces(); ++f)
    out << "3 " << mesh.F(f, 0) << ' ' << mesh.F(f, 1) << ' ' << mesh.F(f, 2) << '\n';
  if (!out) throw OutputError("cannot write '" + path + "'");
}

template <typename Reader>
vtkSmartPointer<vtkPolyData> read_with(const std::string& path) {
  vtkNew<Reader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->ShallowCopy(reader->GetOutput());
  return poly;
}

}  // namespace

std::string file_extension(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  const bool gz = name.size() > 3 && name.substr(name.size() - 3) == ".gz";
  const std::string stem = gz ? name.substr(0, name.size() - 3) : name;
  const auto dot = stem.rfind('.');
  if (dot == std::string::npos) return gz ? ".gz" : "";
  return stem.substr(dot) + (gz ? ".gz" : "");
}

TriMesh read_mesh(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError("mesh '" + path + "' does not exist; check the path");
  const std::string ext = file_extension(path);
  TriMesh mesh;
  if (ext == ".off") {
    mesh = read_off(path);
  } else if (ext == ".ply") {
    mesh = read_ply(path);
  } else if (ext == ".stl") {
    mesh = read_stl(path);
  } else if (ext == ".vtk") {
    mesh = read_legacy_vtk(path);
  } else if (ext == ".obj") {
    mesh = read_obj(path);
  } else {
    vtkSmartPointer<vtkPolyData> poly;
    if (ext == ".vtp")
      poly = read_with<vtkXMLPolyDataReader>(path);

    else
      throw InputError("'" + path + "' has an unknown mesh extension '" + ext +
                       "'; use .vtp .vtk .stl .ply .obj or .off");
    if (!poly || poly->GetNumberOfPoints() == 0)
      throw InputError("cannot read a mesh from '" + path + "'; the file may be corrupt, truncated or empty");
    mesh = from_polydata(poly);
  }
  validate(mesh, path);
  return mesh;
}

void write_mesh(const std::string& path, const TriMesh& mesh) {
  const std::string ext = file_extension(path);
  AtomicOutput out(path);
  const std::string& tmp = out.temp_path();
  if (ext == ".off") {
    write_off(tmp, mesh);
  } else {
    auto poly = to_polydata(mesh);
    int ok = 0;
    if (ext == ".vtp") {
      vtkNew<vtkXMLPolyDataWriter> w;
      w->SetFileName(tmp.c_str());
      w->SetInputData(poly);
      w->SetDataModeToAppended();
      w->SetCompressorTypeToZLib();
      ok = w->Write();
    } else if (ext == ".vtk") {
      vtkNew<vtkPolyDataWriter> w;
      w->SetFileName(tmp.c_str());
      w->SetInputData(poly);
      w->SetFileTypeToBinary();
      ok = w->Write();
    } else if (ext == ".stl") {
      vtkNew<vtkSTLWriter> w;
      w->SetFileName(tmp.c_str());
      w->SetInputData(poly);
      w->SetFileTypeToBinary();
      ok = w->Write();
    } else if (ext == ".ply") {
      vtkNew<vtkPLYWriter> w;
      w->SetFileName(tmp.c_str());
      w->SetInputData(poly);
      w->SetFileTypeToBinary();
      ok = w->Write();
    } else if (ext == ".obj") {
      vtkNew<vtkOBJWriter> w;
      w->SetFileName(tmp.c_str());
      w->SetInputData(poly);
      ok = w->Write();
    } else {
      throw OutputError("'" + path + "' has an unknown mesh extension '" + ext +
                        "'; use .vtp .vtk .stl .ply .obj or .off");
    }
    if (!ok) throw OutputError("cannot write mesh '" + path + "'");
  }
  out.commit();
}

}  // namespace mrsnake
