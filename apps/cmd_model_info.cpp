// mrsnake model-info MODEL: the manifest of a shape model, and a check that synthesis from
// its base and details rebuilds the stored finest level.
#include <chrono>
#include <cstdio>
#include <iostream>

#include "apps/cli.h"
#include "mesh/errors.h"
#include "snake/appearance.h"
#include "model/snake_adapter.h"
#include "snake/reference_image.h"
#include "model/model_io.h"
#include "model/sections.h"

namespace mrsnake::cli {
namespace {

std::string format(const char* fmt, double v) {
  char s[64];
  std::snprintf(s, sizeof s, fmt, v);
  return s;
}

}  // namespace

void add_model_info_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("model-info",
                                 "Print a shape model's manifest and check that its details rebuild the finest level");
  auto model_path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("MODEL", *model_path, "Model folder (made by 'mrsnake build-model')")->required();
  cmd->add_flag("--json", *json, "Print JSON instead of text");
  cmd->footer("Example: mrsnake model-info liver.model --json");
  cmd->callback([=] {
    LoadModelOptions load;
    load.level_meshes = true;
    const ShapeModel model = load_model(*model_path, load);
    const nlohmann::json manifest = read_model_manifest(*model_path);
    const auto t0 = std::chrono::steady_clock::now();
    const RowMatrixX3d S = synthesize(model);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const RowMatrixX3d& stored = model.level_positions.back();
    const Eigen::VectorXd err = (S - stored).rowwise().norm();
    const double diag = bounding_box_diagonal(stored);
    const double max_err = err.maxCoeff(), rms_err = std::sqrt(err.squaredNorm() / err.size());
    const bool ok = max_err <= 1e-9 * diag;
    // The reference image section, decoded (its own checksum and layout checked).
    nlohmann::json reference = nullptr;
    if (const auto it = model.sections.find(kReferenceImageSection); it != model.sections.end())
      reference_image_to_json(reference, deserialize_reference_image(it->second));
    nlohmann::json appearance = nullptr;
    if (const auto it = model.sections.find(kAppearanceSection); it != model.sections.end()) {
      const Appearance decoded = deserialize_appearance(it->second);
      // The same check as segment's: one profile per vertex of every level.
      bool fits = static_cast<int>(decoded.levels.size()) == model.levels() + 1;
      for (std::size_t j = 0; fits && j < decoded.levels.size(); ++j)
        fits = decoded.levels[j].profiles.rows() == model.level_positions[j].rows();
      if (!fits) throw InputError("the model's appearance does not match its levels; rebuild the model");
      appearance = decoded;
    }
    nlohmann::json synthesis = {{"level", model.levels()},
                                {"max_error_mm", max_err},
                                {"rms_error_mm", rms_err},
                                {"max_error_relative_to_diagonal", diag > 0 ? max_err / diag : 0.0},
                                {"bounding_box_diagonal_mm", diag},
                                {"seconds", seconds},
                                {"ok", ok}};
    if (*json) {
      print_json({{"model", *model_path},
                  {"manifest", manifest},
                  {"synthesis", synthesis},
                  {"reference_image", reference},
                  {"appearance", appearance}});
    } else {
      std::cout << *model_path << ": mrsnake model, format version " << manifest["format_version"] << '\n';
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
        if (j > 0)
          std::printf("   %15.6g   %15.6g", model.detail_stats.at(j - 1).rms, model.detail_stats.at(j - 1).max);
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
          if (q.contains(key) && q[key].is_number())
            std::cout << ' ' << key << ' ' << format("%.3g", q[key].get<double>());
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
    if (!ok)
      throw InputError("the details of model '" + *model_path + "' do not rebuild its stored finest level (error " +
                       format("%.3g", max_err) + " mm); the model is inconsistent: rebuild it");
  });
}

}  // namespace mrsnake::cli
