#include "mesh/ply_reader.h"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <vector>

#include "mesh/errors.h"

namespace mrsnake {
namespace {

enum class Format { ascii, binary_le, binary_be };
enum class Type { i8, u8, i16, u16, i32, u32, f32, f64 };

struct Property {
  std::string name;
  bool is_list = false;
  Type count_type = Type::u8;  // lists only
  Type type = Type::f32;
};

struct Element {
  std::string name;
  std::size_t count = 0;
  std::vector<Property> properties;
};

int type_size(Type t) {
  switch (t) {
    case Type::i8:
    case Type::u8: return 1;
    case Type::i16:
    case Type::u16: return 2;
    case Type::i32:
    case Type::u32:
    case Type::f32: return 4;
    case Type::f64: return 8;
  }
  return 0;
}

bool parse_type(const std::string& s, Type& t) {
  static const std::pair<const char*, Type> names[] = {
      {"char", Type::i8},   {"int8", Type::i8},     {"uchar", Type::u8},   {"uint8", Type::u8},
      {"short", Type::i16}, {"int16", Type::i16},   {"ushort", Type::u16}, {"uint16", Type::u16},
      {"int", Type::i32},   {"int32", Type::i32},   {"uint", Type::u32},   {"uint32", Type::u32},
      {"float", Type::f32}, {"float32", Type::f32}, {"double", Type::f64}, {"float64", Type::f64}};
  for (const auto& [name, type] : names)
    if (s == name) {
      t = type;
      return true;
    }
  return false;
}

/// Reads values from the body in the file's format, with bounds checks.
class BodyReader {
 public:
  BodyReader(std::string body, Format format, const std::string& path)
      : body_(std::move(body)), format_(format), path_(path), text_(format == Format::ascii ? body_ : std::string()) {}

  double read(Type t) {
    if (format_ == Format::ascii) {
      double v;
      if (!(text_ >> v)) fail("is truncated or has a malformed number");
      return v;
    }
    const int n = type_size(t);
    if (pos_ + n > body_.size()) fail("is truncated");
    unsigned char b[8];
    std::memcpy(b, body_.data() + pos_, n);
    pos_ += n;
    const bool little = format_ == Format::binary_le;
    unsigned char o[8];
    for (int i = 0; i < n; ++i) o[i] = little ? b[i] : b[n - 1 - i];  // to little-endian
    switch (t) {
      case Type::i8: return static_cast<std::int8_t>(o[0]);
      case Type::u8: return o[0];
      case Type::i16: {
        std::int16_t v;
        std::memcpy(&v, o, 2);
        return v;
      }
      case Type::u16: {
        std::uint16_t v;
        std::memcpy(&v, o, 2);
        return v;
      }
      case Type::i32: {
        std::int32_t v;
        std::memcpy(&v, o, 4);
        return v;
      }
      case Type::u32: {
        std::uint32_t v;
        std::memcpy(&v, o, 4);
        return v;
      }
      case Type::f32: {
        float v;
        std::memcpy(&v, o, 4);
        return v;
      }
      case Type::f64: {
        double v;
        std::memcpy(&v, o, 8);
        return v;
      }
    }
    return 0;
  }

  [[noreturn]] void fail(const std::string& what) const { throw InputError("PLY file '" + path_ + "' " + what); }

 private:
  std::string body_;
  Format format_;
  std::string path_;
  std::istringstream text_;
  std::size_t pos_ = 0;
};

}  // namespace

TriMesh read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open PLY file '" + path + "'");
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto fail = [&](const std::string& what) -> void { throw InputError("PLY file '" + path + "' " + what); };

  const std::size_t header_end = data.find("end_header");
  if (data.compare(0, 3, "ply") != 0 || header_end == std::string::npos) fail("has no valid PLY header");
  std::size_t body_start = data.find('\n', header_end);
  if (body_start == std::string::npos) fail("is truncated after its header");
  ++body_start;

  std::istringstream header(data.substr(0, header_end));
  std::string line;
  std::optional<Format> format;
  std::vector<Element> elements;
  std::getline(header, line);  // "ply"
  while (std::getline(header, line)) {
    std::istringstream s(line);
    std::string word;
    s >> word;
    if (word.empty() || word == "comment" || word == "obj_info") continue;
    if (word == "format") {
      std::string f;
      s >> f;
      if (f == "ascii")
        format = Format::ascii;
      else if (f == "binary_little_endian")
        format = Format::binary_le;
      else if (f == "binary_big_endian")
        format = Format::binary_be;
      else
        fail("has an unknown format '" + f + "'");
    } else if (word == "element") {
      Element e;
      long long count = -1;
      if (!(s >> e.name >> count) || count < 0 || count > 500000000) fail("has a malformed element line");
      e.count = static_cast<std::size_t>(count);
      elements.push_back(e);
    } else if (word == "property") {
      if (elements.empty()) fail("has a property before any element");
      Property p;
      std::string t;
      s >> t;
      if (t == "list") {
        std::string ct, it;
        if (!(s >> ct >> it >> p.name) || !parse_type(ct, p.count_type) || !parse_type(it, p.type))
          fail("has a malformed list property");
        if (p.count_type == Type::f32 || p.count_type == Type::f64) fail("has a list with a non-integer count type");
        p.is_list = true;
      } else if (!parse_type(t, p.type) || !(s >> p.name)) {
        fail("has a malformed property '" + line + "'");
      }
      elements.back().properties.push_back(p);
    } else {
      fail("has an unknown header line '" + line + "'");
    }
  }
  if (!format) fail("has no format line");

  BodyReader body(data.substr(body_start), *format, path);
  TriMesh mesh;
  std::vector<Eigen::RowVector3i> triangles;
  bool have_vertices = false;
  for (const Element& e : elements) {
    const bool is_vertex = e.name == "vertex";
    const bool is_face = e.name == "face";
    int xyz[3] = {-1, -1, -1};
    if (is_vertex) {
      for (std::size_t k = 0; k < e.properties.size(); ++k)
        for (int c = 0; c < 3; ++c)
          if (!e.properties[k].is_list && e.properties[k].name == std::string(1, "xyz"[c]))
            xyz[c] = static_cast<int>(k);
      if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) fail("has no x, y and z vertex properties");
      mesh.V.resize(static_cast<Eigen::Index>(e.count), 3);
      have_vertices = true;
    }
    for (std::size_t i = 0; i < e.count; ++i) {
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        if (!p.is_list) {
          const double v = body.read(p.type);
          for (int c = 0; c < 3; ++c)
            if (is_vertex && static_cast<int>(k) == xyz[c]) mesh.V(static_cast<Eigen::Index>(i), c) = v;
          continue;
        }
        const double count_value = body.read(p.count_type);
        if (!(count_value >= 0 && count_value <= 10000)) fail("has a list of invalid length");
        const auto count = static_cast<std::size_t>(count_value);
        std::vector<int> ids(count);
        for (std::size_t c = 0; c < count; ++c) {
          const double id = body.read(p.type);
          if (!(id >= -2147483648.0 && id <= 2147483647.0)) fail("has a vertex index out of range");
          ids[c] = static_cast<int>(id);
        }
        if (is_face && (p.name == "vertex_indices" || p.name == "vertex_index")) {
          if (count < 3) fail("has a face with fewer than 3 corners");
          for (std::size_t c = 1; c + 1 < count; ++c) triangles.emplace_back(ids[0], ids[c], ids[c + 1]);
        }
      }
    }
  }
  if (!have_vertices) fail("has no vertex element");
  mesh.F.resize(static_cast<Eigen::Index>(triangles.size()), 3);
  for (std::size_t f = 0; f < triangles.size(); ++f) mesh.F.row(static_cast<Eigen::Index>(f)) = triangles[f];
  return mesh;
}

}  // namespace mrsnake
