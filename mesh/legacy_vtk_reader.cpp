#include "mesh/legacy_vtk_reader.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

class Parser {
 public:
  Parser(std::string data, std::string path) : data_(std::move(data)), path_(std::move(path)) {}

  [[noreturn]] void fail(const std::string& what) const { throw InputError("legacy VTK file '" + path_ + "' " + what); }

  std::string line() {
    if (pos_ >= data_.size()) fail("is truncated");
    const std::size_t end = data_.find('\n', pos_);
    std::string l = data_.substr(pos_, end == std::string::npos ? std::string::npos : end - pos_);
    pos_ = end == std::string::npos ? data_.size() : end + 1;
    while (!l.empty() && (l.back() == '\r' || l.back() == ' ')) l.pop_back();
    return l;
  }

  bool at_end() {
    skip_space();
    return pos_ >= data_.size();
  }

  std::string token() {
    skip_space();
    const std::size_t start = pos_;
    while (pos_ < data_.size() && !std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (start == pos_) fail("is truncated");
    return data_.substr(start, pos_ - start);
  }

  long long count() {
    const std::string t = token();
    char* end = nullptr;
    const long long v = std::strtoll(t.c_str(), &end, 10);
    if (end != t.c_str() + t.size() || t.empty() || v < 0 || v > 1000000000LL) fail("has an invalid count '" + t + "'");
    return v;
  }

  /// Reads n values of a VTK type name, ASCII or big-endian binary.
  std::vector<double> values(std::size_t n, const std::string& type, bool binary) {
    std::vector<double> out;
    out.reserve(std::min<std::size_t>(n, data_.size()));
    if (!binary) {
      for (std::size_t i = 0; i < n; ++i) {
        const std::string t = token();
        char* end = nullptr;
        const double v = std::strtod(t.c_str(), &end);
        if (end != t.c_str() + t.size()) fail("has a malformed number '" + t.substr(0, 20) + "'");
        out.push_back(v);
      }
      return out;
    }
    // Binary data starts right after the keyword line's newline.
    const int size = type_size(type);
    if (pos_ + static_cast<unsigned long long>(n) * size > data_.size()) fail("is truncated in its binary data");
    for (std::size_t i = 0; i < n; ++i) {
      unsigned char b[8];
      for (int k = 0; k < size; ++k) b[k] = static_cast<unsigned char>(data_[pos_ + size - 1 - k]);  // BE -> LE
      pos_ += size;
      out.push_back(decode(b, type));
    }
    return out;
  }

  int type_size(const std::string& type) const {
    if (type == "float" || type == "int" || type == "unsigned_int") return 4;
    if (type == "double" || type == "vtktypeint64" || type == "long" || type == "unsigned_long" ||
        type == "vtktypeuint64")
      return 8;
    if (type == "short" || type == "unsigned_short") return 2;
    if (type == "char" || type == "unsigned_char") return 1;
    fail("has an unsupported data type '" + type + "'");
  }

  void skip_line_end() {
    while (pos_ < data_.size() && (data_[pos_] == ' ' || data_[pos_] == '\r')) ++pos_;
    if (pos_ < data_.size() && data_[pos_] == '\n') ++pos_;
  }

 private:
  void skip_space() {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
  }

  double decode(const unsigned char* b, const std::string& type) const {
    if (type == "float") {
      float v;
      std::memcpy(&v, b, 4);
      return v;
    }
    if (type == "double") {
      double v;
      std::memcpy(&v, b, 8);
      return v;
    }
    if (type == "int") {
      std::int32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    if (type == "unsigned_int") {
      std::uint32_t v;
      std::memcpy(&v, b, 4);
      return v;
    }
    if (type == "short") {
      std::int16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    if (type == "unsigned_short") {
      std::uint16_t v;
      std::memcpy(&v, b, 2);
      return v;
    }
    if (type == "char") return static_cast<std::int8_t>(b[0]);
    if (type == "unsigned_char") return b[0];
    std::int64_t v;
    std::memcpy(&v, b, 8);
    return static_cast<double>(v);
  }

  std::string data_;
  std::string path_;
  std::size_t pos_ = 0;
};

}  // namespace

TriMesh read_legacy_vtk(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open '" + path + "'");
  Parser p(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()), path);
  if (p.line().rfind("# vtk DataFile Version", 0) != 0) p.fail("has no '# vtk DataFile Version' header");
  p.line();  // title
  const std::string encoding = p.line();
  if (encoding != "ASCII" && encoding != "BINARY") p.fail("is neither ASCII nor BINARY");
  const bool binary = encoding == "BINARY";
  if (p.token() != "DATASET" || p.token() != "POLYDATA") p.fail("is not a POLYDATA dataset");

  TriMesh mesh;
  std::vector<Eigen::RowVector3i> triangles;
  bool have_points = false;
  while (!p.at_end()) {
    const std::string section = p.token();
    if (section == "POINTS") {
      const long long n = p.count();
      const std::string type = p.token();
      p.skip_line_end();
      const auto xyz = p.values(static_cast<std::size_t>(3 * n), type, binary);
      mesh.V.resize(n, 3);
      for (long long i = 0; i < n; ++i) mesh.V.row(i) << xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2];
      have_points = true;
    } else if (section == "VERTICES" || section == "LINES" || section == "POLYGONS" || section == "TRIANGLE_STRIPS") {
      const long long a = p.count(), b = p.count();
      std::vector<std::vector<long long>> cells;
      // 5.1 layout: "POLYGONS nOffsets nConn" then OFFSETS and CONNECTIVITY arrays.
      p.skip_line_end();
      {
        const std::string next = p.token();
        if (next == "OFFSETS") {
          const std::string otype = p.token();
          p.skip_line_end();
          const auto offsets = p.values(static_cast<std::size_t>(a), otype, binary);
          if (p.token() != "CONNECTIVITY") p.fail("has OFFSETS without CONNECTIVITY");
          const std::string ctype = p.token();
          p.skip_line_end();
          const auto conn = p.values(static_cast<std::size_t>(b), ctype, binary);
          for (long long c = 0; c + 1 < a; ++c) {
            const double lo = offsets[c], hi = offsets[c + 1];
            if (!(lo >= 0 && hi >= lo && hi <= static_cast<double>(b))) p.fail("has inconsistent cell offsets");
            std::vector<long long> ids;
            for (auto k = static_cast<long long>(lo); k < static_cast<long long>(hi); ++k)
              ids.push_back(static_cast<long long>(conn[k]));
            cells.push_back(std::move(ids));
          }
        } else {
          // Classic layout: a cells, b integers in all ("k i1 .. ik" per cell). The first
          // token already read is the first cell's k.
          std::vector<double> flat;
          if (binary) p.fail("uses the classic binary cell layout, which mrsnake does not read; re-save it");
          char* end = nullptr;
          flat.push_back(std::strtod(next.c_str(), &end));
          if (end != next.c_str() + next.size()) p.fail("has a malformed number '" + next.substr(0, 20) + "'");
          if (b < 1) p.fail("has an invalid cell array size");
          const auto rest = p.values(static_cast<std::size_t>(b - 1), "int", false);
          flat.insert(flat.end(), rest.begin(), rest.end());
          std::size_t k = 0;
          for (long long c = 0; c < a; ++c) {
            if (k >= flat.size()) p.fail("has fewer cell entries than it declares");
            const double len = flat[k++];
            if (!(len >= 0 && k + static_cast<std::size_t>(len) <= flat.size())) p.fail("has a cell of invalid size");
            std::vector<long long> ids;
            for (int i = 0; i < static_cast<int>(len); ++i) ids.push_back(static_cast<long long>(flat[k++]));
            cells.push_back(std::move(ids));
          }
        }
      }
      if (section == "POLYGONS")
        for (const auto& ids : cells) {
          if (ids.size() < 3) p.fail("has a polygon with fewer than 3 corners");
          for (std::size_t c = 1; c + 1 < ids.size(); ++c)
            triangles.emplace_back(static_cast<int>(ids[0]), static_cast<int>(ids[c]), static_cast<int>(ids[c + 1]));
        }
    } else if (section == "POINT_DATA" || section == "CELL_DATA" || section == "FIELD" || section == "METADATA") {
      break;  // attributes are not needed
    } else {
      p.fail("has an unknown section '" + section.substr(0, 20) + "'");
    }
  }
  if (!have_points) p.fail("has no POINTS");
  mesh.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t f = 0; f < triangles.size(); ++f) mesh.F.row(static_cast<Eigen::Index>(f)) = triangles[f];
  return mesh;
}

}  // namespace mrsnake
