#include "mesh/obj_reader.h"

#include <fstream>
#include <sstream>
#include <vector>

#include "mesh/errors.h"

namespace mrsnake {

TriMesh read_obj(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open OBJ file '" + path + "'");
  std::vector<Eigen::RowVector3d> points;
  std::vector<Eigen::RowVector3i> triangles;
  std::string line;
  for (long number = 1; std::getline(in, line); ++number) {
    const auto fail = [&](const std::string& what) {
      throw InputError("OBJ file '" + path + "' line " + std::to_string(number) + ": " + what);
    };
    std::istringstream s(line);
    std::string kind;
    s >> kind;
    if (kind == "v") {
      Eigen::RowVector3d p;
      if (!(s >> p[0] >> p[1] >> p[2])) fail("a vertex needs three coordinates");
      points.push_back(p);
    } else if (kind == "f") {
      std::vector<int> corners;
      std::string corner;
      while (s >> corner) {
        // The vertex index is what comes before the first '/'.
        const std::string index = corner.substr(0, corner.find('/'));
        std::size_t used = 0;
        long i = 0;
        try {
          i = std::stol(index, &used);
        } catch (const std::exception&) {
          fail("malformed face corner '" + corner.substr(0, 20) + "'");
        }
        if (used != index.size() || i == 0) fail("malformed face corner '" + corner.substr(0, 20) + "'");
        const long resolved = i > 0 ? i - 1 : static_cast<long>(points.size()) + i;  // negative: relative
        if (resolved < 0 || resolved >= static_cast<long>(points.size()))
          fail("face corner " + std::to_string(i) + " names a vertex not defined before it");
        corners.push_back(static_cast<int>(resolved));
      }
      if (corners.size() < 3) fail("a face needs at least 3 corners");
      for (std::size_t c = 1; c + 1 < corners.size(); ++c)
        triangles.emplace_back(corners[0], corners[c], corners[c + 1]);
    }
  }
  TriMesh mesh;
  mesh.V.resize(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) mesh.V.row(static_cast<Eigen::Index>(i)) = points[i];
  mesh.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t f = 0; f < triangles.size(); ++f) mesh.F.row(static_cast<Eigen::Index>(f)) = triangles[f];
  return mesh;
}

}  // namespace mrsnake
