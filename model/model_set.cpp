#include "model/model_set.h"

#include <filesystem>
#include <set>

#include "mesh/atomic_file.h"
#include "mesh/errors.h"
#include "mesh/json_text.h"
#include "model/model_files.h"

namespace fs = std::filesystem;

namespace mrsnake {
namespace {

using namespace model_files;

constexpr const char* kStructuresFolder = "structures";
constexpr const char* kReferenceFile = "reference_image.bin";

std::string structure_path(int value) { return std::string(kStructuresFolder) + "/" + std::to_string(value); }

nlohmann::json frame_json(const std::optional<PhysicalFrame>& frame) {
  if (!frame) return nullptr;
  return {{"units", "mm"},
          {"size", frame->size},
          {"spacing", frame->spacing},
          {"origin", frame->origin},
          {"direction", frame->direction}};
}

std::optional<PhysicalFrame> frame_of(const nlohmann::json& j) {
  if (j.is_null()) return std::nullopt;
  PhysicalFrame f;
  f.size = j.at("size").get<std::array<std::size_t, 3>>();
  f.spacing = j.at("spacing").get<std::array<double, 3>>();
  f.origin = j.at("origin").get<std::array<double, 3>>();
  f.direction = j.at("direction").get<std::array<double, 9>>();
  return f;
}

void check_writable(const ModelSet& set) {
  if (set.structures.empty()) throw std::invalid_argument("save_model_set: no structure");
  std::set<int> values;
  for (const ModelStructure& s : set.structures)
    if (s.value <= 0 || !values.insert(s.value).second)
      throw std::invalid_argument("save_model_set: structure values must be positive and distinct");
}

// Each structure as a version-1 folder of its own, and its entry in the manifest.
nlohmann::json write_structures(const fs::path& temp, const ModelSet& set, const ProgressFn& progress) {
  nlohmann::json entries = nlohmann::json::array();
  for (std::size_t i = 0; i < set.structures.size(); ++i) {
    const ModelStructure& s = set.structures[i];
    report(progress, "write " + s.label.name, static_cast<double>(i) / set.structures.size());
    const std::string path = structure_path(s.value);
    save_model((temp / path).string(), s.model);
    const nlohmann::json own = read_model_manifest((temp / path).string());
    entries.push_back({{"value", s.value},
                       {"name", s.label.name},
                       {"color", s.label.color},
                       {"path", path},
                       {"manifest_fnv1a64", own.at("manifest_fnv1a64")}});
  }
  return entries;
}

nlohmann::json skipped_json(const std::vector<SkippedLabel>& skipped) {
  nlohmann::json list = nlohmann::json::array();
  for (const SkippedLabel& s : skipped) list.push_back({{"value", s.value}, {"name", s.name}, {"reason", s.reason}});
  return list;
}

// The structure folder a manifest entry names: structures/<its value>, nothing else.
fs::path structure_folder(const fs::path& dir, const nlohmann::json& entry, const std::string& folder) {
  const int value = entry.at("value").get<int>();
  const std::string path = entry.at("path").get<std::string>();
  if (value <= 0 || path != structure_path(value))
    throw InputError("model '" + folder + "' lists the structure " + std::to_string(value) + " at '" + path +
                     "' (expected " + structure_path(value) + "); the manifest is damaged: rebuild the model");
  return dir / path;
}

ModelStructure read_structure(const fs::path& dir, const nlohmann::json& entry, const std::string& folder,
                              const LoadModelOptions& options) {
  const fs::path sub = structure_folder(dir, entry, folder);
  ModelStructure s;
  s.value = entry.at("value").get<int>();
  s.label.name = entry.at("name").get<std::string>();
  s.label.color = entry.at("color").get<std::array<int, 3>>();
  const nlohmann::json own = read_model_manifest(sub.string());
  if (own.at("manifest_fnv1a64") != entry.at("manifest_fnv1a64"))
    throw InputError("structure " + std::to_string(s.value) + " of model '" + folder +
                     "' is not the one its manifest lists (its checksum differs); rebuild the model");
  s.model = load_model(sub.string(), options);
  return s;
}

// A version-1 folder: one structure, named after its label.
ModelSet read_single_structure(const std::string& folder, const LoadModelOptions& options) {
  ModelSet set;
  set.format_version = kStructureFormatVersion;
  ModelStructure s;
  s.model = load_model(folder, options);
  s.value = s.model.source_label.value_or(1);
  s.label = {default_label_name(s.value), default_label_color(s.value)};
  set.source_image = s.model.source_image;
  set.physical_frame = s.model.physical_frame;
  set.build_options = s.model.build_options;
  set.structures.push_back(std::move(s));
  return set;
}

}  // namespace

void save_model_set(const std::string& folder, const ModelSet& set, const ProgressFn& progress,
                    const std::function<void(const std::string& temp_folder)>& write_extras) {
  check_writable(set);
  const std::string final_path = writable_model_path(folder);
  AtomicDirectory out(final_path, model_folder());
  const fs::path temp = out.temp_path();

  nlohmann::json m;
  m["format"] = "mrsnake-model";
  m["format_version"] = kModelFormatVersion;
  m["source"] = set.source_image.empty() ? nlohmann::json(nullptr) : nlohmann::json{{"image", set.source_image}};
  m["physical_frame"] = frame_json(set.physical_frame);
  m["structures"] = write_structures(temp, set, progress);
  m["skipped"] = skipped_json(set.skipped);
  if (!set.build_options.is_null()) m["build_options"] = set.build_options;
  m["sections"] = nlohmann::json::object();
  if (!set.reference_image.empty()) {
    write_bytes(temp / kReferenceFile, set.reference_image);
    m["sections"]["reference_image"] = file_entry(temp, kReferenceFile);
  }
  m["manifest_fnv1a64"] = manifest_checksum(m);
  const std::string text = json_text(m, 2) + "\n";
  write_bytes(temp / kManifest, std::vector<std::uint8_t>(text.begin(), text.end()));
  if (write_extras) write_extras(temp.string());
  out.commit();
  report(progress, "write model", 1.0);
}

ModelSet load_model_set(const std::string& folder, const LoadModelOptions& options) {
  const nlohmann::json m = read_model_manifest(folder);
  if (m["format_version"].get<int>() == kStructureFormatVersion) return read_single_structure(folder, options);
  const fs::path dir = normalized_folder(folder);
  try {
    ModelSet set;
    if (!m.at("source").is_null()) set.source_image = m["source"].at("image").get<std::string>();
    set.physical_frame = frame_of(m.at("physical_frame"));
    if (m.contains("build_options")) set.build_options = m["build_options"];
    for (const nlohmann::json& s : m.at("skipped"))
      set.skipped.push_back(
          {s.at("value").get<int>(), s.at("name").get<std::string>(), s.at("reason").get<std::string>()});
    std::set<int> values;
    for (const nlohmann::json& entry : m.at("structures")) {
      set.structures.push_back(read_structure(dir, entry, folder, options));
      if (!values.insert(set.structures.back().value).second)
        throw InputError("model '" + folder + "' lists the structure " + std::to_string(set.structures.back().value) +
                         " twice; rebuild the model");
    }
    if (set.structures.empty()) throw InputError("model '" + folder + "' holds no structure; rebuild the model");
    if (const auto& sections = m.at("sections"); sections.contains("reference_image"))
      set.reference_image = read_part(dir, sections["reference_image"], "shared reference image");
    return set;
  } catch (const nlohmann::json::exception& e) {
    throw InputError("model.json of '" + folder + "' has a missing or malformed field (" + e.what() +
                     "); rebuild the model");
  }
}

}  // namespace mrsnake
