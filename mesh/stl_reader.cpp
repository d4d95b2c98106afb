#include "mesh/stl_reader.h"

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <vector>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

/// Collects corners, merging identical coordinates.
class CornerMerger {
 public:
  int add(const std::array<double, 3>& p) {
    const auto [it, inserted] = index_.try_emplace(p, static_cast<int>(points_.size()));
    if (inserted) points_.push_back(p);
    return it->second;
  }
  TriMesh finish(const std::vector<Eigen::RowVector3i>& triangles) const {
    TriMesh m;
    m.V.resize(static_cast<Eigen::Index>(points_.size()), 3);
    for (std::size_t i = 0; i < points_.size(); ++i)
      m.V.row(static_cast<Eigen::Index>(i)) << points_[i][0], points_[i][1], points_[i][2];
    m.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
    for (std::size_t f = 0; f < triangles.size(); ++f) m.F.row(static_cast<Eigen::Index>(f)) = triangles[f];
    return m;
  }

 private:
  std::map<std::array<double, 3>, int> index_;
  std::vector<std::array<double, 3>> points_;
};

}  // namespace

TriMesh read_stl(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open STL file '" + path + "'");
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto fail = [&](const std::string& what) { throw InputError("STL file '" + path + "' " + what); };
  CornerMerger corners;
  std::vector<Eigen::RowVector3i> triangles;

  // Binary when the size matches the count exactly; ASCII files start with "solid" but so
  // do some binary headers, hence the size test first.
  std::uint32_t count = 0;
  if (data.size() >= 84) std::memcpy(&count, data.data() + 80, 4);
  if (data.size() >= 84 && data.size() == 84 + 50ull * count) {
    triangles.reserve(count);
    for (std::uint32_t t = 0; t < count; ++t) {
      const char* rec = data.data() + 84 + 50ull * t + 12;  // skip the normal
      Eigen::RowVector3i tri;
      for (int c = 0; c < 3; ++c) {
        float xyz[3];
        std::memcpy(xyz, rec + 12 * c, 12);
        tri[c] = corners.add({xyz[0], xyz[1], xyz[2]});
      }
      triangles.push_back(tri);
    }
  } else {
    if (data.compare(0, 5, "solid") != 0)
      fail("is neither ASCII (no 'solid') nor a binary STL of consistent size; it may be truncated");
    std::istringstream text(data);
    std::string word;
    std::vector<int> loop;
    while (text >> word) {
      if (word == "vertex") {
        std::array<double, 3> p{};
        if (!(text >> p[0] >> p[1] >> p[2])) fail("has a malformed vertex");
        loop.push_back(corners.add(p));
      } else if (word == "endloop") {
        if (loop.size() != 3) fail("has a facet without exactly 3 vertices");
        triangles.emplace_back(loop[0], loop[1], loop[2]);
        loop.clear();
      }
    }
    if (!loop.empty()) fail("is truncated inside a facet");
  }
  if (triangles.empty()) fail("has no triangle");
  return corners.finish(triangles);
}

}  // namespace mrsnake
