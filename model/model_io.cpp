#include "model/model_io.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "mesh/atomic_file.h"
#include "model/byte_codec.h"
#include "mesh/errors.h"
#include "mesh/json_text.h"
#include "mesh/mesh_io.h"
#include "model/model_files.h"

namespace fs = std::filesystem;

namespace mrsnake {
namespace {

using namespace model_files;

constexpr char kMagic[8] = {'M', 'R', 'S', 'N', 'K', 'D', 'E', 'T'};
constexpr std::size_t kHeaderBytes = 48;
constexpr std::uint32_t kDetailsVersion = 1;
constexpr int kMaxLevels = 12;
constexpr const char* kDetails = "details.bin";
constexpr const char* kFormatName = "mrsnake-model";

bool valid_section_name(const std::string& name) {
  if (name.empty() || name.size() > 64 || name == "details") return false;
  for (char c : name)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  return true;
}

std::uint32_t scheme_code(PredictScheme p) { return p == PredictScheme::linear ? 0u : 1u; }

std::vector<std::uint8_t> encode_details(const ShapeModel& m, const std::vector<int>& counts) {
  ByteWriter w(std::vector<std::uint8_t>(kMagic, kMagic + 8));
  w.put<std::uint32_t>(kDetailsVersion);
  w.put<std::uint32_t>(scheme_code(m.wavelet.predict));
  w.put<std::uint32_t>(m.wavelet.update ? 1u : 0u);
  w.put<std::uint32_t>(m.wavelet.frame == DetailFrame::local ? 1u : 0u);
  w.put<double>(m.wavelet.degenerate_frame_tolerance);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(m.levels()));
  w.put<std::uint32_t>(static_cast<std::uint32_t>(m.base.rows()));
  w.put<std::uint32_t>(static_cast<std::uint32_t>(m.base_faces.rows()));
  w.put<std::uint32_t>(0);
  for (int n : counts) w.put<std::uint32_t>(static_cast<std::uint32_t>(n));
  for (Eigen::Index f = 0; f < m.base_faces.rows(); ++f)
    for (int k = 0; k < 3; ++k) w.put<std::int32_t>(m.base_faces(f, k));
  for (Eigen::Index v = 0; v < m.base.rows(); ++v)
    for (int k = 0; k < 3; ++k) w.put<double>(m.base(v, k));
  for (const RowMatrixX3d& D : m.details)
    for (Eigen::Index v = 0; v < D.rows(); ++v)
      for (int k = 0; k < 3; ++k) w.put<double>(D(v, k));
  w.put<std::uint64_t>(fnv1a64(w.bytes().data(), w.bytes().size()));
  return w.take();
}

/// Parses details.bin into the model; every defect is an InputError naming the file.
void decode_details(const std::vector<std::uint8_t>& bytes, const std::string& where, ShapeModel& m,
                    std::vector<int>& counts) {
  const auto fail = [&](const std::string& why) { return InputError(where + " " + why + "; rebuild the model"); };
  if (bytes.size() < kHeaderBytes + 8)
    throw fail("is truncated (" + std::to_string(bytes.size()) + " bytes, shorter than its header)");
  if (std::memcmp(bytes.data(), kMagic, 8) != 0) throw fail("is not a mrsnake details file (bad magic bytes)");
  ByteReader r(bytes, 0, fail("is truncated"));
  r.get<std::uint64_t>();  // magic
  const std::uint32_t version = r.get<std::uint32_t>();
  if (version > kDetailsVersion)
    throw InputError(where + " has format version " + std::to_string(version) + ", newer than this mrsnake reads (" +
                     std::to_string(kDetailsVersion) + "); upgrade mrsnake or rebuild the model");
  if (version == 0) throw fail("has an invalid format version 0");
  const std::uint32_t predict = r.get<std::uint32_t>(), update = r.get<std::uint32_t>(), frame = r.get<std::uint32_t>();
  const double tolerance = r.get<double>();
  const std::uint32_t levels = r.get<std::uint32_t>(), n0 = r.get<std::uint32_t>(), m0 = r.get<std::uint32_t>();
  r.get<std::uint32_t>();  // reserved
  if (predict > 1 || update > 1 || frame > 1 || !(tolerance >= 0 && tolerance < 1))
    throw fail("has an unknown wavelet scheme code");
  if (levels > kMaxLevels)
    throw fail("claims " + std::to_string(levels) + " levels (at most " + std::to_string(kMaxLevels) + ")");
  if (n0 < 3 || m0 < 1 || n0 > 50000000u || m0 > 100000000u) throw fail("has invalid base mesh counts");
  // Sizes: checked before reading any array, with 64-bit arithmetic.
  std::uint64_t expected = kHeaderBytes + 4ull * (levels + 1);
  if (bytes.size() < expected + 8) throw fail("is truncated (" + std::to_string(bytes.size()) + " bytes)");
  counts.assign(levels + 1, 0);
  std::uint64_t previous = 0;
  for (std::uint32_t j = 0; j <= levels; ++j) {
    const std::uint32_t n = r.get<std::uint32_t>();
    if (n <= previous || n > 2000000000u) throw fail("has vertex counts that do not grow with the level");
    counts[j] = static_cast<int>(n);
    previous = n;
  }
  if (static_cast<std::uint32_t>(counts[0]) != n0) throw fail("has inconsistent base vertex counts");
  expected += 12ull * m0 + 24ull * n0 + 24ull * (static_cast<std::uint64_t>(counts[levels]) - n0) + 8ull;
  if (bytes.size() < expected)
    throw fail("is truncated (" + std::to_string(bytes.size()) + " of " + std::to_string(expected) + " bytes)");
  if (bytes.size() > expected)
    throw fail("has " + std::to_string(bytes.size() - expected) + " unexpected trailing bytes");
  std::uint64_t stored = 0;
  for (int i = 0; i < 8; ++i) stored |= static_cast<std::uint64_t>(bytes[expected - 8 + i]) << (8 * i);
  if (stored != fnv1a64(bytes.data(), expected - 8))
    throw fail("was altered or corrupted (its checksum does not match)");

  m.wavelet.predict = predict == 0 ? PredictScheme::linear : PredictScheme::butterfly;
  m.wavelet.update = update == 1;
  m.wavelet.frame = frame == 1 ? DetailFrame::local : DetailFrame::global;
  m.wavelet.degenerate_frame_tolerance = tolerance;
  m.base_faces.resize(m0, 3);
  for (std::uint32_t f = 0; f < m0; ++f)
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = r.get<std::int32_t>();
      if (v < 0 || static_cast<std::uint32_t>(v) >= n0) throw fail("has a base face with a vertex index out of range");
      m.base_faces(f, k) = v;
    }
  m.base.resize(n0, 3);
  for (std::uint32_t v = 0; v < n0; ++v)
    for (int k = 0; k < 3; ++k) m.base(v, k) = r.get<double>();
  m.details.assign(levels, RowMatrixX3d());
  for (std::uint32_t j = 1; j <= levels; ++j) {
    RowMatrixX3d& D = m.details[j - 1];
    D.resize(counts[j] - counts[j - 1], 3);
    for (Eigen::Index v = 0; v < D.rows(); ++v)
      for (int k = 0; k < 3; ++k) D(v, k) = r.get<double>();
    if (!D.allFinite()) throw fail("holds non-finite details at level " + std::to_string(j));
  }
  if (!m.base.allFinite()) throw fail("holds non-finite base positions");
}

nlohmann::json stats_to_json(const DetailStats& s) {
  return {{"level", s.level}, {"count", s.count}, {"energy", s.energy},
          {"rms", s.rms},     {"max", s.max},     {"degenerate_frames", s.degenerate_frames}};
}

}  // namespace

std::uint64_t fnv1a64(const std::uint8_t* data, std::size_t size, std::uint64_t state) {
  std::uint64_t h = state;
  for (std::size_t i = 0; i < size; ++i) {
    h ^= data[i];
    h *= 1099511628211ull;
  }
  return h;
}

void save_model(const std::string& folder, const ShapeModel& model, const ProgressFn& progress,
                const std::function<void(const std::string& temp_folder)>& write_extras) {
  const int L = model.levels();
  if (static_cast<int>(model.level_positions.size()) != L + 1)
    throw std::invalid_argument("save_model: the model needs its levels S_0..S_L (make_model fills them)");
  for (const auto& [name, blob] : model.sections)
    if (!valid_section_name(name))
      throw std::invalid_argument("save_model: invalid section name '" + name + "' (use [a-z0-9_]+, not 'details')");
  const SubdivisionConnectivity conn = model.connectivity();

  const std::string final_path = writable_model_path(folder);
  // Written into a temporary folder beside the final one, renamed into place at the end
  // (and removed on an error or an interrupt). Only a model folder is replaced.
  AtomicDirectory out(final_path, model_folder());
  const fs::path temp = out.temp_path();

  report(progress, "write model", 0.0);
  nlohmann::json files;
  write_bytes(temp / kDetails, encode_details(model, conn.vertex_counts));
  files["details"] = file_entry(temp, kDetails);
  nlohmann::json levels = nlohmann::json::array();
  for (int j = 0; j <= L; ++j) {
    const std::string name = "level_" + std::to_string(j) + ".vtp";
    write_mesh((temp / name).string(), TriMesh{model.level_positions[j], conn.faces[j]});
    levels.push_back(file_entry(temp, name));
    report(progress, "write model", (j + 1.0) / (L + 2.0));
  }
  files["levels"] = levels;
  nlohmann::json sections = nlohmann::json::object();
  for (const auto& [name, blob] : model.sections) {
    write_bytes(temp / (name + ".bin"), blob);
    sections[name] = file_entry(temp, name + ".bin");
  }

  nlohmann::json m;
  m["format"] = kFormatName;
  m["format_version"] = kStructureFormatVersion;
  m["source"] = model.source_image.empty() && !model.source_label
                    ? nlohmann::json(nullptr)
                    : nlohmann::json{{"image", model.source_image},
                                     {"label", model.source_label ? nlohmann::json(*model.source_label)
                                                                  : nlohmann::json(nullptr)}};
  if (model.source_component && !m["source"].is_null()) m["source"]["component"] = *model.source_component;
  if (model.physical_frame) {
    const PhysicalFrame& f = *model.physical_frame;
    m["physical_frame"] = {
        {"units", "mm"}, {"size", f.size}, {"spacing", f.spacing}, {"origin", f.origin}, {"direction", f.direction}};
  } else {
    m["physical_frame"] = nullptr;
  }
  m["levels"] = L;
  m["vertex_counts"] = conn.vertex_counts;
  std::vector<Eigen::Index> face_counts;
  for (const auto& F : conn.faces) face_counts.push_back(F.rows());
  m["face_counts"] = face_counts;
  m["wavelet"] = {{"predict", to_string(model.wavelet.predict)},
                  {"update", model.wavelet.update ? "mean_keeping" : "none"},
                  {"detail_frame", to_string(model.wavelet.frame)},
                  {"degenerate_frame_tolerance", model.wavelet.degenerate_frame_tolerance}};
  nlohmann::json stats = nlohmann::json::array();
  for (const DetailStats& s : model.detail_stats) stats.push_back(stats_to_json(s));
  m["detail_stats"] = stats;
  m["remesh_quality"] = model.remesh_quality;
  if (!model.scale.is_null()) m["scale"] = model.scale;
  if (!model.build_options.is_null()) m["build_options"] = model.build_options;
  nlohmann::json timings = nlohmann::json::array();
  for (const auto& [stage, seconds] : model.timings) timings.push_back({{"stage", stage}, {"seconds", seconds}});
  m["timings"] = timings;
  m["files"] = files;
  m["sections"] = sections;
  m["manifest_fnv1a64"] = manifest_checksum(m);
  write_bytes(temp / kManifest, [&] {
    const std::string text = json_text(m, 2) + "\n";
    return std::vector<std::uint8_t>(text.begin(), text.end());
  }());
  if (write_extras) write_extras(temp.string());

  out.commit();
  report(progress, "write model", 1.0);
}

nlohmann::json read_model_manifest(const std::string& folder) {
  const fs::path dir = normalized_folder(folder);
  std::error_code ec;
  if (!fs::exists(dir, ec)) throw InputError("model folder '" + folder + "' does not exist; check the path");
  if (!fs::is_directory(dir, ec)) throw InputError("'" + folder + "' is not a model folder", Remedy::make_model);
  if (!fs::is_regular_file(dir / kManifest, ec))
    throw InputError("model '" + folder + "' has no model.json; it is incomplete or not a model: rebuild it");
  const std::vector<std::uint8_t> bytes = read_bytes(dir / kManifest);
  nlohmann::json m = nlohmann::json::parse(bytes.begin(), bytes.end(), nullptr, /*allow_exceptions=*/false);
  if (m.is_discarded() || !m.is_object())
    throw InputError("model.json of '" + folder + "' is not valid JSON; it is truncated or corrupt: rebuild the model");
  if (!m.contains("format") || m["format"] != kFormatName)
    throw InputError("model.json of '" + folder +
                     "' is not a mrsnake model manifest (no \"format\": \"mrsnake-model\")");
  if (!m.contains("format_version") || !m["format_version"].is_number_integer())
    throw InputError("model.json of '" + folder +
                     "' has no integer format_version; the file is corrupt: rebuild the model");
  const auto version = m["format_version"].get<std::int64_t>();
  if (version > kModelFormatVersion)
    throw InputError("model '" + folder + "' has format version " + std::to_string(version) +
                     ", newer than this mrsnake reads (" + std::to_string(kModelFormatVersion) +
                     "); upgrade mrsnake or rebuild the model");
  if (version < 1)
    throw InputError("model '" + folder + "' has an invalid format version " + std::to_string(version) +
                     "; rebuild the model");
  if (!m.contains("manifest_fnv1a64") || !m["manifest_fnv1a64"].is_string() ||
      m["manifest_fnv1a64"].get<std::string>() != manifest_checksum(m))
    throw InputError("model.json of '" + folder + "' was altered (its checksum does not match); rebuild the model");
  return m;
}

ShapeModel load_model(const std::string& folder, const LoadModelOptions& options) {
  const nlohmann::json m = read_model_manifest(folder);
  if (m["format_version"].get<int>() != kStructureFormatVersion)
    throw InputError("'" + folder + "' is a model of structures (format version " +
                     std::to_string(m["format_version"].get<int>()) +
                     "), not one structure's folder: read it as such (load_model_set), or give one of its "
                     "structures/<value> folders");
  const fs::path dir = normalized_folder(folder);
  const std::string where = "model '" + folder + "'";
  try {
    ShapeModel model;
    std::vector<int> counts;
    const nlohmann::json& files = m.at("files");
    decode_details(read_part(dir, files.at("details"), "base mesh and details"), "part 'details.bin' of " + where,
                   model, counts);
    // The manifest and the binary part must agree.
    const int L = m.at("levels").get<int>();
    if (L != model.levels() || m.at("vertex_counts").get<std::vector<int>>() != counts ||
        m.at("wavelet").at("predict").get<std::string>() != to_string(model.wavelet.predict) ||
        m.at("wavelet").at("detail_frame").get<std::string>() != to_string(model.wavelet.frame))
      throw InputError(where +
                       ": model.json and details.bin disagree on the levels, counts or scheme; rebuild the model");
    SubdivisionConnectivity conn;
    try {
      conn = model.connectivity();
    } catch (const TopologyError& e) {
      throw InputError("part 'details.bin' of " + where + " holds an invalid base mesh (" + e.what() +
                       "); rebuild the model");
    }
    if (conn.vertex_counts != counts)
      throw InputError("part 'details.bin' of " + where +
                       " has vertex counts that do not match its base mesh's subdivision; rebuild the model");
    const nlohmann::json& levels = files.at("levels");
    if (!levels.is_array() || static_cast<int>(levels.size()) != L + 1)
      throw InputError(where + ": model.json lists " + std::to_string(levels.size()) + " level meshes for " +
                       std::to_string(L) + " levels; rebuild the model");
    for (int j = 0; j <= L; ++j) {
      read_part(dir, levels[j], "mesh of level " + std::to_string(j));  // presence, size, checksum
      if (!options.level_meshes) continue;
      const TriMesh mesh = read_mesh((dir / levels[j].at("path").get<std::string>()).string());
      if (mesh.num_vertices() != conn.vertex_counts[j] || mesh.F != conn.faces[j])
        throw InputError(where + ": level_" + std::to_string(j) + ".vtp does not have the connectivity of level " +
                         std::to_string(j) + "; rebuild the model");
      model.level_positions.push_back(mesh.V);
    }
    for (const auto& [name, entry] : m.at("sections").items()) {
      if (!valid_section_name(name))
        throw InputError(where + ": model.json lists an invalid section name '" + name + "'");
      model.sections[name] = read_part(dir, entry, "section '" + name + "'");
    }
    // Provenance and reports.
    if (!m.at("source").is_null()) {
      model.source_image = m["source"].at("image").get<std::string>();
      if (!m["source"].at("label").is_null()) model.source_label = m["source"]["label"].get<int>();
      if (m["source"].contains("component")) model.source_component = m["source"]["component"].get<int>();
    }
    if (!m.at("physical_frame").is_null()) {
      const nlohmann::json& f = m["physical_frame"];
      PhysicalFrame frame;
      frame.size = f.at("size").get<std::array<std::size_t, 3>>();
      frame.spacing = f.at("spacing").get<std::array<double, 3>>();
      frame.origin = f.at("origin").get<std::array<double, 3>>();
      frame.direction = f.at("direction").get<std::array<double, 9>>();
      model.physical_frame = frame;
    }
    model.remesh_quality = m.at("remesh_quality");
    if (m.contains("scale")) model.scale = m["scale"];
    if (m.contains("build_options")) model.build_options = m["build_options"];
    for (const nlohmann::json& t : m.at("timings"))
      model.timings.emplace_back(t.at("stage").get<std::string>(), t.at("seconds").get<double>());
    for (const nlohmann::json& s : m.at("detail_stats")) {
      DetailStats d;
      d.level = s.at("level").get<int>();
      d.count = s.at("count").get<int>();
      d.energy = s.at("energy").get<double>();
      d.rms = s.at("rms").get<double>();
      d.max = s.at("max").get<double>();
      d.degenerate_frames = s.at("degenerate_frames").get<int>();
      model.detail_stats.push_back(d);
    }
    return model;
  } catch (const nlohmann::json::exception& e) {
    throw InputError("model.json of '" + folder + "' has a missing or malformed field (" + e.what() +
                     "); rebuild the model");
  }
}

}  // namespace mrsnake
