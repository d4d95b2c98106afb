// mrsnake model-info MODEL: the manifest of a shape model, and a check that synthesis from
// its base and details rebuilds the stored finest level.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <vector>
#include <iostream>

#include "apps/cli.h"
#include "mesh/errors.h"
#include "snake/appearance.h"
#include "model/snake_adapter.h"
#include "snake/reference_image.h"
#include "model/model_io.h"
#include "model/model_set.h"
#include "model/sections.h"

namespace mrsnake::cli {
namespace {

std::string format(const char* fmt, double v) {
  char s[64];
  std::snprintf(s, sizeof s, fmt, v);
  return s;
}

// What model-info says of one structure: its manifest, the synthesis check, the decoded
// appearance and reference crop (each section's own checksum and layout checked).
struct StructureInfo {
  nlohmann::json manifest, synthesis, appearance, reference;
  double max_err = 0, rms_err = 0, diag = 0, seconds = 0;
  bool ok = false;
};

StructureInfo structure_info(const ShapeModel& model, const nlohmann::json& manifest) {
  StructureInfo info;
  info.manifest = manifest;
  const auto t0 = std::chrono::steady_clock::now();
  const RowMatrixX3d S = synthesize(model);
  info.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const RowMatrixX3d& stored = model.level_positions.back();
  const Eigen::VectorXd err = (S - stored).rowwise().norm();
  info.diag = bounding_box_diagonal(stored);
  info.max_err = err.maxCoeff();
  info.rms_err = std::sqrt(err.squaredNorm() / err.size());
  info.ok = info.max_err <= 1e-9 * info.diag;
  if (const auto it = model.sections.find(kReferenceImageSection); it != model.sections.end())
    reference_image_to_json(info.reference, deserialize_reference_image(it->second));
  if (const auto it = model.sections.find(kAppearanceSection); it != model.sections.end()) {
    const Appearance decoded = deserialize_appearance(it->second);
    // The same check as segment's: one profile per vertex of every level.
    bool fits = static_cast<int>(decoded.levels.size()) == model.levels() + 1;
    for (std::size_t j = 0; fits && j < decoded.levels.size(); ++j)
      fits = decoded.levels[j].profiles.rows() == model.level_positions[j].rows();
    if (!fits) throw InputError("the model's appearance does not match its levels; rebuild the model");
    info.appearance = decoded;
  }
  info.synthesis = {{"level", model.levels()},
                    {"max_error_mm", info.max_err},
                    {"rms_error_mm", info.rms_err},
                    {"max_error_relative_to_diagonal", info.diag > 0 ? info.max_err / info.diag : 0.0},
                    {"bounding_box_diagonal_mm", info.diag},
                    {"seconds", info.seconds},
                    {"ok", info.ok}};
  return info;
}

// The text of one structure, as model-info prints a model of one structure.
void print_structure_text(const std::string& model_path, const ShapeModel& model, const StructureInfo& info) {
  const nlohmann::json& manifest = info.manifest;
  const nlohmann::json& appearance = info.appearance;
  const nlohmann::json& reference = info.reference;
  const double max_err = info.max_err, rms_err = info.rms_err, diag = info.diag, seconds = info.seconds;
  const bool ok = info.ok;
  std::cout << model_path << ": mrsnake model, format version " << manifest["format_version"] << '\n';
  if (!model.source_image.empty() || model.source_label)
    std::cout << "  source            " << model.source_image
              << (model.source_label ? ", label " + std::to_string(*model.source_label) : std::string())
              << (model.source_component ? ", its part " + std::to_string(*model.source_component) + " by size"
                                         : std::string())
              << '\n';
  if (model.physical_frame) {
    const PhysicalFrame& f = *model.physical_frame;
    std::cout << "  image grid        " << f.size[0] << "x" << f.size[1] << "x" << f.size[2] << " voxels of "
              << f.spacing[0] << "x" << f.spacing[1] << "x" << f.spacing[2] << " mm\n";
  }
  std::cout << "  wavelet           " << manifest["wavelet"]["predict"].get<std::string>() << " predict, "
            << manifest["wavelet"]["update"].get<std::string>() << " update, "
            << manifest["wavelet"]["detail_frame"].get<std::string>() << " details\n"
            << "  levels            " << model.levels() << '\n'
            << "  level   vertices      faces   detail rms (mm)   detail max (mm)\n";
  const auto& vc = manifest["vertex_counts"];
  const auto& fc = manifest["face_counts"];
  for (int j = 0; j <= model.levels(); ++j) {
    std::printf("  %5d %10d %10d", j, vc[j].get<int>(), fc[j].get<int>());
    if (j > 0) std::printf("   %15.6g   %15.6g", model.detail_stats.at(j - 1).rms, model.detail_stats.at(j - 1).max);
    std::printf("\n");
  }
  std::fflush(stdout);
  if (!model.remesh_quality.is_null()) {
    // The finest level's quality (mesh/quality.h keys), the rest is in model.json.
    const nlohmann::json& q = model.remesh_quality.contains("finest_level_quality")
                                  ? model.remesh_quality["finest_level_quality"]
                                  : model.remesh_quality;
    std::cout << "  remesh quality   ";
    for (const char* key : {"min_angle_deg", "q_min", "q_mean", "pct_valence6_interior", "edge_length_cv"})
      if (q.contains(key) && q[key].is_number()) std::cout << ' ' << key << ' ' << format("%.3g", q[key].get<double>());
    if (const nlohmann::json& m = model.remesh_quality;
        m.contains("finest_level_self_intersections") && m["finest_level_self_intersections"].is_number_integer())
      std::cout << " self_intersections " << m["finest_level_self_intersections"].get<long long>();
    std::cout << '\n';
  }
  if (model.scale.is_object()) {
    // The structure's size and the defaults build-model derived from it (model.json "scale").
    const nlohmann::json& sc = model.scale;
    const auto number = [&sc](const char* key, const char* fmt) {
      return sc.contains(key) && sc[key].is_number() ? format(fmt, sc[key].get<double>()) : std::string("-");
    };
    std::cout << "  structure         " << number("volume_mm3", "%.4g") << " mm3, equivalent radius "
              << number("equivalent_radius_mm", "%.3g") << " mm; marching cubes "
              << number("marching_cubes_spacing_mm", "%.3g") << " mm"
              << (sc.contains("reference_margin_mm") && sc["reference_margin_mm"].is_number()
                      ? ", reference margin " + number("reference_margin_mm", "%.3g") + " mm"
                      : std::string())
              << '\n';
    if (sc.contains("fit_to_label") && sc["fit_to_label"].is_object()) {
      const nlohmann::json& f = sc["fit_to_label"];
      std::cout << "  fit to its label  Dice " << format("%.4f", f.value("dice", 0.0)) << ", volume ratio "
                << format("%.3f", f.value("volume_ratio", 0.0)) << '\n';
    }
  }
  if (!model.timings.empty()) {
    std::cout << "  timings (s)      ";
    for (const auto& [stage, s] : model.timings) std::cout << ' ' << stage << ' ' << format("%.3f", s);
    std::cout << '\n';
  }
  if (!model.sections.empty()) {
    std::cout << "  sections         ";
    for (const auto& [name, blob] : model.sections) std::cout << ' ' << name << " (" << blob.size() << " bytes)";
    std::cout << '\n';
  }
  if (!appearance.is_null()) {
    // Per level: where the learned profiles are centred, which decides whether segment
    // deforms the levels finer than the image (snake/segment.h).
    std::cout << "  appearance        " << appearance["samples_per_profile"] << " samples per profile; centred on";
    for (const auto& c : appearance["profiles_centred_on"]) std::cout << ' ' << c.get<std::string>();
    std::cout << " (levels 0.." << appearance["levels"].get<int>() - 1 << ")\n";
  }
  if (!reference.is_null()) {
    const auto& sz = reference["size"];
    const auto& sp = reference["spacing"];
    const auto& ex = reference["extent_mm"];
    std::cout << "  reference image   " << sz[0] << "x" << sz[1] << "x" << sz[2] << " voxels of "
              << format("%.3g", sp[0].get<double>()) << "x" << format("%.3g", sp[1].get<double>()) << "x"
              << format("%.3g", sp[2].get<double>()) << " mm (" << format("%.0f", ex[0].get<double>()) << "x"
              << format("%.0f", ex[1].get<double>()) << "x" << format("%.0f", ex[2].get<double>())
              << " mm), for segment --init register\n";
  }
  std::cout << "  synthesis of S_" << model.levels() << " from S_0 and the details: max error "
            << format("%.3g", max_err) << " mm (" << format("%.3g", diag > 0 ? max_err / diag : 0.0)
            << " of the diagonal), rms " << format("%.3g", rms_err) << " mm, " << format("%.2f", seconds * 1e3)
            << " ms: " << (ok ? "ok" : "MISMATCH") << '\n';
}

// A structure's own folder: the model itself for a version-1 folder.
std::string structure_folder(const std::string& model_path, const ModelSet& set, const ModelStructure& s) {
  if (set.format_version == kStructureFormatVersion) return model_path;
  return (std::filesystem::path(model_path) / "structures" / std::to_string(s.value)).string();
}

nlohmann::json set_json(const std::string& model_path, const ModelSet& set, const std::vector<StructureInfo>& infos) {
  nlohmann::json structures = nlohmann::json::array();
  for (std::size_t i = 0; i < infos.size(); ++i) {
    const ModelStructure& s = set.structures[i];
    structures.push_back({{"value", s.value},
                          {"name", s.label.name},
                          {"color", s.label.color},
                          {"manifest", infos[i].manifest},
                          {"synthesis", infos[i].synthesis},
                          {"reference_image", infos[i].reference},
                          {"appearance", infos[i].appearance}});
  }
  nlohmann::json skipped = nlohmann::json::array();
  for (const SkippedLabel& k : set.skipped)
    skipped.push_back({{"value", k.value}, {"name", k.name}, {"reason", k.reason}});
  nlohmann::json shared = nullptr;
  if (!set.reference_image.empty()) reference_image_to_json(shared, deserialize_reference_image(set.reference_image));
  nlohmann::json j = {{"model", model_path},
                      {"format_version", set.format_version},
                      {"structures", structures},
                      {"skipped", skipped},
                      {"shared_reference_image", shared}};
  // A model of one structure also answers with that structure's keys, as a version-1 folder did.
  if (infos.size() == 1)
    for (const char* key : {"manifest", "synthesis", "reference_image", "appearance"}) j[key] = structures[0][key];
  if (infos.size() == 1 && !shared.is_null()) j["reference_image"] = shared;
  return j;
}

// A model of several structures: one row per structure, the skipped labels, the shared crop.
void print_set_text(const std::string& model_path, const ModelSet& set, const std::vector<StructureInfo>& infos) {
  std::cout << model_path << ": mrsnake model of " << set.structures.size() << " structure"
            << (set.structures.size() == 1 ? "" : "s") << ", format version " << set.format_version << '\n';
  if (!set.source_image.empty()) std::cout << "  source            " << set.source_image << '\n';
  std::cout << "  value  levels   vertices      faces   fit Dice  synthesis  name\n";
  for (std::size_t i = 0; i < infos.size(); ++i) {
    const ModelStructure& s = set.structures[i];
    const nlohmann::json& m = infos[i].manifest;
    const nlohmann::json& sc = s.model.scale;
    const double dice = sc.is_object() && sc.contains("fit_to_label") ? sc["fit_to_label"].value("dice", 0.0) : 0.0;
    std::printf("  %5d %7d %10d %10d   %8s  %9s  %s\n", s.value, s.model.levels(), m["vertex_counts"].back().get<int>(),
                m["face_counts"].back().get<int>(), dice > 0 ? format("%.4f", dice).c_str() : "-",
                infos[i].ok ? "ok" : "MISMATCH", s.label.name.c_str());
  }
  for (const SkippedLabel& k : set.skipped)
    std::printf("  skipped %d (%s): %s\n", k.value, k.name.c_str(), k.reason.c_str());
  std::fflush(stdout);
  if (!set.reference_image.empty()) {
    nlohmann::json r;
    reference_image_to_json(r, deserialize_reference_image(set.reference_image));
    std::cout << "  reference image   " << r["size"][0] << "x" << r["size"][1] << "x" << r["size"][2]
              << " voxels, shared by every structure, for segment --init register\n";
  }
  if (set.structures.size() == 1)
    print_structure_text(structure_folder(model_path, set, set.structures[0]), set.structures[0].model, infos[0]);
}

}  // namespace

void add_model_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "model-info",
      "Print a shape model's structures and manifest, and check that its details rebuild each finest level");
  auto model_path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("MODEL", *model_path, "Model folder (made by 'mrsnake build-model')")->required();
  cmd->add_flag("--json", *json, "Print JSON instead of text");
  cmd->footer("Example: mrsnake model-info liver.model --json");
  cmd->callback([=] {
    LoadModelOptions load;
    load.level_meshes = true;
    const ModelSet set = load_model_set(*model_path, load);
    std::vector<StructureInfo> infos;
    for (const ModelStructure& s : set.structures)
      infos.push_back(structure_info(s.model, read_model_manifest(structure_folder(*model_path, set, s))));
    if (*json)
      print_json(set_json(*model_path, set, infos));
    else if (set.format_version == kStructureFormatVersion)
      print_structure_text(*model_path, set.structures[0].model, infos[0]);
    else
      print_set_text(*model_path, set, infos);
    for (std::size_t i = 0; i < infos.size(); ++i)
      if (!infos[i].ok)
        throw InputError("the details of structure " + std::to_string(set.structures[i].value) + " of model '" +
                         *model_path + "' do not rebuild its stored finest level (error " +
                         format("%.3g", infos[i].max_err) + " mm); the model is inconsistent: rebuild it");
  });
}

}  // namespace mrsnake::cli
