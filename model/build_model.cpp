#include "model/build_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>

#include <nlohmann/json.hpp>

#include "mesh/distance.h"
#include "mesh/label_repair.h"
#include "mesh/option_checks.h"
#include "mesh/stage_clock.h"
#include "mesh/quality.h"
#include "model/build_model_json.h"
#include "model/snake_adapter.h"
#include "snake/rasterize.h"
#include "snake/reference_image.h"

namespace mrsnake {

RemeshOptions model_remesh_preset() {
  RemeshOptions o;
  o.fit.rounds = 0;                 // the vertices stay on the reference surface,
  o.untangle.max_rounds = 0;        // even where the finest level crosses itself (a warning)
  o.sizing.curvature_weight = 1.0;  // denser where the organ bends
  o.keep_input_locator = true;      // the report page measures every level against the input
  return o;
}

namespace {

// The label's surface, with the spacing and smoothing it was extracted with.
void extract_surface(const Volume& labels, const BuildModelOptions& options, const ProgressFn& progress,
                     BuiltModel& built) {
  const ModelSurfaceOptions& o = options.surface;
  built.mc_spacing_mm = o.mc_spacing_mm >= 0 ? o.mc_spacing_mm : default_marching_cubes_spacing(built.scale);
  // The resampled occupancy has no staircase left to smooth away: a few iterations do.
  built.smoothing_iterations =
      o.smoothing_iterations >= 0 ? o.smoothing_iterations : (built.mc_spacing_mm > 0 ? 5 : 20);
  LabelSurfaceOptions mc;
  mc.smoothing_iterations = built.smoothing_iterations;
  mc.max_closing_radius = o.close_tunnels;
  mc.remove_spurs = o.remove_spurs;
  mc.resample_spacing_mm = built.mc_spacing_mm;
  built.surface = extract_label_surface(labels, options.label, mc, progress);
  const LabelSurface& s = built.surface;
  if (s.genus_before_repair > 0 && s.closing_radius == 0)
    throw LabelGenusError(
        "label " + std::to_string(options.label) + " has a genus-" + std::to_string(s.genus_before_repair) +
            " surface (tunnels through it), but a model needs genus 0" +
            (o.close_tunnels > 0
                 ? "; a closing of radius up to " + std::to_string(o.close_tunnels) + " voxels did not remove them"
                 : std::string()),
        s.genus_before_repair);
}

// The semi-regular hierarchy of the surface; its time split into the parameterization and the levels.
void remesh_surface(const BuildModelOptions& options, const ProgressFn& progress, BuiltModel& built,
                    StageClock& clock) {
  const double sampling_mm = built.mc_spacing_mm > 0 ? built.mc_spacing_mm : built.scale.finest_voxel_mm;
  RemeshOptions& ro = built.remesh;
  ro = options.remesh;
  ro.levels = options.levels;
  ro.target_faces = options.faces > 0 ? options.faces : default_face_count(built.surface.mesh, sampling_mm);
  ro.compute_stats = options.report.level_stats;
  ro.progress = progress;
  built.hierarchy = remesh(built.surface.mesh, ro);
  clock.end("remesh");
  double levels_seconds = 0;
  for (const RemeshLevel& level : built.hierarchy.levels) levels_seconds += level.seconds;
  auto& laps = built.timings;
  const double remesh_seconds = laps.back().second;
  laps.pop_back();
  laps.emplace_back("parameterization", std::max(0.0, remesh_seconds - levels_seconds));
  laps.emplace_back("levels", levels_seconds);
}

// The finest level against the label it came from: the label as modelled (its part K with
// a component), and, when other parts were dropped, the better of the label and its two
// largest parts (the surface kept is the largest by faces, which need not be the largest by
// voxels; a tunnel closing may have joined two parts).
LabelFit fit_to_source(const TriMesh& finest, const Volume& labels, int label, bool parts_dropped) {
  const Volume raster = rasterize_mesh(finest, labels, 1.0f);
  LabelFit best = label_fit_of_raster(raster, labels, label);
  for (int part = 1; parts_dropped && part <= 2; ++part) {
    try {
      const LabelFit f = label_fit_of_raster(raster, keep_label_part(labels, label, part), label);
      if (f.dice > best.dice) best = f;
    } catch (const InputError&) {  // fewer parts than that
      break;
    }
  }
  return best;
}

// A model that has lost its organ is refused here, before anything is written.
void check_fit(const Volume& labels, const BuildModelOptions& options, BuiltModel& built) {
  const bool parts_dropped = !built.surface.dropped_component_faces.empty() && options.component == 0;
  built.fit =
      fit_to_source(built.hierarchy.mesh(built.hierarchy.connectivity.levels()), labels, options.label, parts_dropped);
  if (built.fit.dice >= kMinLabelFitDice || options.allow_poor_fit) return;
  throw PoorFitError(describe_poor_fit(built.fit), built);
}

// The profiles and the reference crop that the segmentation matches and registers.
void add_image_sections(const Volume& image, const BuildModelOptions& options, const ProgressFn& progress,
                        BuiltModel& built) {
  report(progress, "appearance", 0.0);
  built.alignment = add_appearance(built.model, image, options.appearance);
  built.reference_margin_mm =
      options.reference_margin_mm >= 0 ? options.reference_margin_mm : default_reference_margin(built.scale);
  ReferenceImageOptions ro;
  ro.margin_mm = *built.reference_margin_mm;
  add_reference_image(built.model, image, ro);
}

// model.json's provenance, quality and `scale`: the structure's size, every default derived
// from it, and the fit.
void record_provenance(const Volume& labels, const BuildModelOptions& options, BuiltModel& built) {
  ShapeModel& model = built.model;
  model.source_label = options.label;
  model.build_options = options;
  if (options.component > 0) model.source_component = options.component;
  PhysicalFrame frame;
  frame.size = labels.size;
  frame.spacing = labels.spacing;
  frame.origin = labels.origin;
  frame.direction = labels.direction;
  model.physical_frame = frame;
  const RemeshResult& h = built.hierarchy;
  nlohmann::json quality = remesh_report(h, built.remesh);
  quality["finest_level_quality"] = mesh_quality(h.mesh(h.connectivity.levels()));
  quality["finest_level_self_intersections"] = built.self_intersections;
  quality["input_faces"] = built.surface.mesh.num_faces();
  quality["marching_cubes"] = {{"spacing_mm", built.mc_spacing_mm},
                               {"smoothing_iterations", built.smoothing_iterations},
                               {"faces", built.surface.mesh.num_faces()}};
  model.remesh_quality = quality;
  nlohmann::json scale = built.scale;
  scale["marching_cubes_spacing_mm"] = built.mc_spacing_mm;
  scale["smoothing_iterations"] = built.smoothing_iterations;
  scale["faces"] = static_cast<int>(h.connectivity.faces.back().rows());
  scale["reference_margin_mm"] =
      built.reference_margin_mm ? nlohmann::json(*built.reference_margin_mm) : nlohmann::json();
  scale["fit_to_label"] = built.fit;
  model.scale = scale;
}

// The same surface split without relaxation: the paper's baseline, for the report page.
RemeshResult remesh_unrelaxed(const BuiltModel& built) {
  RemeshOptions plain = built.remesh;
  plain.relax = RelaxMode::none;
  plain.compute_stats = false;
  plain.keep_input_locator = false;
  return remesh(built.surface.mesh, plain);
}

}  // namespace

void validate(const BuildModelOptions& o) {
  require(o.component >= 0 && o.component <= 1000, "component", "0 (the whole label) to 1000");
  require(std::isfinite(o.surface.mc_spacing_mm) && o.surface.mc_spacing_mm <= 100, "surface.mc_spacing_mm",
          "at most 100 (mm; 0 = the voxels' surface, negative = derived)");
  require(o.surface.smoothing_iterations <= 1000, "surface.smoothing_iterations", "at most 1000 (negative = derived)");
  require(o.surface.close_tunnels >= 0 && o.surface.close_tunnels <= 20, "surface.close_tunnels", "0 to 20 voxels");
  require(o.faces == 0 || (o.faces >= 16 && o.faces <= 50000000), "faces", "0 (derived) or 16 to 50000000");
  require(o.levels >= 0 && o.levels <= 10, "levels", "0 (from faces) to 10");
  require(o.faces == 0 || o.levels == 0, "faces", "0 when levels is given");
  require(std::isfinite(o.reference_margin_mm) && o.reference_margin_mm <= 1000, "reference_margin_mm",
          "at most 1000 (mm; negative = derived)");
  // The model's resolution is the top-level faces or levels: remesh's own would be overwritten.
  const RemeshOptions preset = model_remesh_preset();
  require(o.remesh.levels == preset.levels, "remesh.levels", "left out (give the top-level levels)");
  require(o.remesh.target_faces == preset.target_faces, "remesh.target_faces",
          "left out (give the top-level faces, or --faces)");
  check_options(o.remesh, "remesh.");
}

std::string describe_poor_fit(const LabelFit& fit) {
  char text[256];
  std::snprintf(text, sizeof text,
                "the model's finest level covers its label with Dice %.3f (volume %+.0f %%, below the %.2f accepted)",
                fit.dice, 100.0 * (fit.volume_ratio - 1.0), kMinLabelFitDice);
  return text;
}

BuiltModel build_model(const Volume& labels_in, const Volume* image, const BuildModelOptions& options,
                       const ProgressFn& progress) {
  validate(options);
  BuiltModel built;
  StageClock clock(built.timings);
  // Only a chosen part is a new volume; the whole label is used in place, not copied.
  std::optional<Volume> part;
  if (options.component > 0) part = keep_label_part(labels_in, options.label, options.component);
  const Volume& labels = part ? *part : labels_in;
  built.scale = measure_structure(labels, options.label);
  extract_surface(labels, options, progress, built);
  clock.end("marching_cubes");

  remesh_surface(options, progress, built, clock);

  report(progress, "wavelet analysis", 0.0);
  built.model = make_model(built.hierarchy.connectivity, built.hierarchy.levels.back().positions, options.wavelet);
  report(progress, "wavelet analysis", 1.0);
  clock.end("analysis");

  check_fit(labels, options, built);
  built.self_intersections = count_self_intersections(built.hierarchy.mesh(built.hierarchy.connectivity.levels()));
  clock.end("label_fit");

  if (image != nullptr) {
    add_image_sections(*image, options, progress, built);
    clock.end("appearance");
  }
  record_provenance(labels, options, built);
  if (options.report.compare_unrelaxed) built.unrelaxed = remesh_unrelaxed(built);
  built.model.timings = built.timings;
  return built;
}

}  // namespace mrsnake
