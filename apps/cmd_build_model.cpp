// mrsnake build-model --labels IMG --label N -o MODEL: marching cubes, semi-regular
// remeshing and wavelet analysis, written as a model folder (wavelets/model_io.h).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <iostream>

#include "apps/cli.h"
#include "apps/report/remesh_page.h"
#include "mesh/atomic_file.h"
#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/label_repair.h"
#include "mesh/marching_cubes.h"
#include "mesh/quality.h"
#include "remesh/remesh.h"
#include "snake/label_fit.h"
#include "snake/model_bridge.h"
#include "snake/rasterize.h"
#include "snake/structure_scale.h"
#include "wavelets/model_io.h"

namespace mrsnake::cli {

namespace {
// What the user chose of the options that shape the surface, for the poor-fit message.
struct SurfaceChoices {
  double mc_spacing = 0;
  bool spacing_given = false, faces_given = false;
  int closing_radius = 0;  // the tunnel closing applied, in voxels (0: none)
};

// Why a model lost its organ, and what to type about it.
std::string poor_fit_message(const LabelFit& fit, const StructureScale& scale, const SurfaceChoices& c) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "the model's finest level covers its label with Dice %.3f (volume %+.0f %%, below the %.2f accepted)",
                fit.dice, 100.0 * (fit.volume_ratio - 1.0), kMinLabelFitDice);
  std::string cause;
  if (c.closing_radius > 0) {
    cause = "; closing the label's tunnels (radius " + std::to_string(c.closing_radius) +
            " voxels) changed its shape: fill the tunnels in the label volume, or give --close-tunnels 0 to see them";
  } else if (c.mc_spacing > 0 && c.spacing_given) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "; the marching-cubes spacing %.3g mm is coarse for a structure of radius %.3g mm: "
                  "give a smaller --mc-spacing (e.g. %.3g)",
                  c.mc_spacing, scale.equivalent_radius_mm, scale.finest_voxel_mm);
    cause = text;
  } else {
    cause = "; the label may be too thin or ragged for a closed genus-0 model: check it with 'mrsnake mc'";
    if (!c.spacing_given) cause += ", try --mc-spacing 0";
    if (!c.faces_given) cause += ", or more --faces";
  }
  return buf + cause;
}

// The finest level against the label it came from: the label as modelled (its part K with
// --component), and, when other parts were dropped, the better of the label and its two
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

// model.json's `scale`: the structure's size, every default derived from it, the fit.
nlohmann::json scale_record(const StructureScale& scale, double mc_spacing, int smoothing, int finest_faces,
                            const std::optional<double>& reference_margin_mm, const LabelFit& fit) {
  nlohmann::json j = scale;
  j["marching_cubes_spacing_mm"] = mc_spacing;
  j["smoothing_iterations"] = smoothing;
  j["faces"] = finest_faces;
  j["reference_margin_mm"] = reference_margin_mm ? nlohmann::json(*reference_margin_mm) : nlohmann::json();
  j["fit_to_label"] = fit;
  return j;
}
}  // namespace

void add_build_model_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("build-model",
                                 "Build a multiresolution shape model from one label of a label image: marching cubes, "
                                 "semi-regular remeshing, lifting-wavelet analysis");
  struct Args {
    std::string labels, output, predict = "butterfly", image;
    int label = 1, levels = 0, faces = 0, smooth = 20, close_tunnels = 3, component = 0;
    double mc_spacing = -1;  // derived from the structure: see --mc-spacing
    bool full_report = false, json = false, compare_unrelaxed = false, allow_poor_fit = false;
    double reference_margin_mm = -1;  // derived from the structure: see --reference-margin
    SphereMap sphere_map = SphereMap::automatic;
    // Off by default, unlike remesh: a model's vertices stay on the reference surface. With the
    // fit, the segmentation bench's 128³ Dice fell by 0.0002-0.0004 on 9 of 10 cases
    // (bench/segment).
    int fit_rounds = 0;
    // 1, unlike remesh's 0.5: more vertices where the organ bends. With 0.5 the real-data Dice
    // fell on 3 of 4 structures (left hippocampus 0.9499 -> 0.9446) and the synthetic ones moved
    // by -0.0022..+0.0007 (bench/segment, bench/real_data.sh). 0.5 buys triangle quality, and
    // the snake measured better with the denser sampling of the bends.
    double curvature_weight = 1.0;
    std::string profile_alignment = "auto";
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--labels", a->labels, "Label volume (.nii .nii.gz .nrrd .mha .mhd .gipl, or a DICOM folder)")
      ->required();
  cmd->add_option("--label", a->label, "Label value of the object")->required();
  cmd->add_option("-o,--output", a->output, "Output model folder (replaced if it is already a model)")->required();
  auto* levels = cmd->add_option("--levels", a->levels, "Number of levels L (1:4 splits of the base mesh)")
                     ->check(CLI::Range(1, 10));
  auto* faces =
      cmd->add_option("--faces", a->faces,
                      "Wanted face count of the finest level (default: triangles with edges of half the surface's "
                      "sampling length, the marching-cubes spacing or the finest voxel, 1024 to 32768)")
          ->check(CLI::Range(16, 50000000));
  levels->excludes(faces);
  add_sphere_map_option(*cmd, a->sphere_map);
  add_fit_rounds_option(*cmd, a->fit_rounds);
  cmd->add_option("--predict", a->predict, "Wavelet predict step: butterfly (default) or linear")
      ->check(CLI::IsMember({"butterfly", "linear"}));
  auto* smooth =
      cmd->add_option("--smooth", a->smooth,
                      "Windowed-sinc smoothing iterations of the marching-cubes surface (default 5, or 20 with "
                      "--mc-spacing 0 to remove the voxel staircase; 0 = none)")
          ->check(CLI::Range(0, 1000));
  cmd->add_option("--mc-spacing", a->mc_spacing,
                  "Marching cubes on the label's Gaussian-smoothed occupancy resampled to this isotropic spacing in mm "
                  "(default: the structure's equivalent radius / 60 if the voxels are finer than that, else 0): a "
                  "smooth surface of a size the model needs; 0 = the voxels' own surface (as 'mrsnake mc', much slower "
                  "on a large fine label)")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_option("--close-tunnels", a->close_tunnels,
                  "If the label's surface is not genus 0, close the label with radii up to this many voxels until it "
                  "is (as 'mrsnake mc --close-tunnels'; default 3: a label's stray tunnels of a voxel or two are "
                  "closed with a warning, and the fit check refuses a closing that changed the shape); 0 = no repair")
      ->check(CLI::Range(0, 20));
  cmd->add_option(
         "--component", a->component,
         "Model only the label's K-th largest connected part (1 = the largest), e.g. one of a left and a right "
         "organ that share a label; its other parts count as background, in the appearance too; 0 = the "
         "whole label (its largest surface is modelled)")
      ->check(CLI::Range(0, 1000));
  auto* image_option = cmd->add_option(
      "--image", a->image,
      "Reference intensity image of the labels (same physical space): stores the appearance "
      "(profiles along the normals, inside/outside statistics) that 'mrsnake segment' matches, and a "
      "crop of the image around the organ that 'mrsnake segment --init register' registers to a new image");
  cmd->add_option("--profile-alignment", a->profile_alignment,
                  "Where the profiles of --image are centred: 'edges' (the image's edge within half a voxel step of "
                  "the label's surface: the label's rounding does not pass into the segmentations), 'labels' (the "
                  "label's surface: the labels define the boundary, as an expert's on a real image), or 'auto' "
                  "(edges when the profiles are clean steps, as in synthetic images)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "edges", "labels"}))
      ->needs(image_option);
  cmd->add_option("--reference-margin", a->reference_margin_mm,
                  "Margin (mm) of the stored reference image crop around the organ (with --image; default 6 "
                  "equivalent radii of the structure)")
      ->check(CLI::Range(0.0, 1000.0));
  cmd->add_flag("--allow-poor-fit", a->allow_poor_fit,
                "Write the model even when its finest level, rasterized on the label's grid, has a Dice below 0.90 "
                "against the label (otherwise refused with exit code 5)");
  cmd->add_flag("--full-report", a->full_report, "Quality and distance to the input at every level (slower)");
  cmd->add_flag("--compare-unrelaxed", a->compare_unrelaxed,
                "Also remesh without relaxation and compare both in MODEL/report.html (a second remeshing run)");
  cmd->add_flag("--json", a->json, "Print a JSON summary");
  cmd->footer(
      "Example: mrsnake build-model --labels liver-labels.nii.gz --label 255 --image liver.nii.gz -o liver.model "
      "--faces 32768\n"
      "Every default length follows the structure's size and voxels (model.json 'scale' records them). A label\n"
      "with tunnels of up to 3 voxels (genus > 0) is closed by default, e.g. the liver of abdomen-ct-small-seg.nii.gz\n"
      "(label 5); wider ones need a larger --close-tunnels.");
  cmd->callback([a, smooth] {
    using clock = std::chrono::steady_clock;
    const auto progress = terminal_progress();
    std::vector<std::pair<std::string, double>> timings;
    auto t = clock::now();
    const auto lap = [&](const std::string& stage) {
      const auto now = clock::now();
      timings.emplace_back(stage, std::chrono::duration<double>(now - t).count());
      t = now;
    };
    const auto t_start = t;

    report(progress, "reading " + a->labels, 0.0);
    const Volume labels =
        a->component > 0 ? keep_label_part(read_volume(a->labels), a->label, a->component) : read_volume(a->labels);
    lap("read");

    // Every default length follows the structure and its voxels (snake/structure_scale.h).
    const StructureScale scale = measure_structure(labels, a->label);
    const double mc_spacing = a->mc_spacing >= 0 ? a->mc_spacing : default_marching_cubes_spacing(scale);
    // The resampled occupancy has no staircase left to smooth away: a few iterations do.
    const int smoothing = smooth->count() == 0 && mc_spacing > 0 ? 5 : a->smooth;
    LabelSurfaceOptions mc;
    mc.smoothing_iterations = smoothing;
    mc.max_closing_radius = a->close_tunnels;
    mc.resample_spacing_mm = mc_spacing;
    const LabelSurface surface = extract_label_surface(labels, a->label, mc, progress);
    // Say how to repair it here, where the flag is known, not after the costly part.
    if (surface.genus_before_repair > 0 && surface.closing_radius == 0)
      throw TopologyError(
          "label " + std::to_string(a->label) + " has a genus-" + std::to_string(surface.genus_before_repair) +
          " surface (tunnels through it), but a model needs genus 0; " +
          (a->close_tunnels > 0 ? "a closing of radius up to " + std::to_string(a->close_tunnels) +
                                      " voxels did not remove them: try a larger --close-tunnels"
                                : std::string("drop --close-tunnels 0 (the default closes them up to 3 voxels)")) +
          ", or fill them in the label volume");
    if (!surface.dropped_component_faces.empty())
      warn("label " + std::to_string(a->label) + " has " + std::to_string(surface.components_found) +
           " connected surfaces; the model uses the largest" +
           (a->component > 0 ? std::string()
                             : std::string(" (--component K models the K-th largest part of the label)")));
    if (surface.closing_radius > 0)
      warn("label " + std::to_string(a->label) + " had a genus-" + std::to_string(surface.genus_before_repair) +
           " surface; closed its tunnels with a radius of " + std::to_string(surface.closing_radius) + " voxels");
    lap("marching_cubes");

    const double sampling_mm = mc_spacing > 0 ? mc_spacing : scale.finest_voxel_mm;
    const int faces = a->faces > 0 ? a->faces : default_face_count(surface.mesh, sampling_mm);
    RemeshOptions ro;
    ro.levels = a->levels;
    ro.target_faces = faces;
    ro.sphere_map = a->sphere_map;
    ro.fit.rounds = a->fit_rounds;
    ro.sizing.curvature_weight = a->curvature_weight;
    ro.keep_input_locator = true;  // for the report page, built while the map is solved
    ro.compute_stats = a->full_report;
    ro.progress = progress;
    const RemeshResult hierarchy = remesh(surface.mesh, ro);
    lap("remesh");
    // Split the remesh time into its parameterization and its levels when it reports them.
    double levels_seconds = 0;
    for (const RemeshLevel& level : hierarchy.levels) levels_seconds += level.seconds;
    const double remesh_seconds = timings.back().second;
    timings.pop_back();
    timings.emplace_back("parameterization", std::max(0.0, remesh_seconds - levels_seconds));
    timings.emplace_back("levels", levels_seconds);

    WaveletOptions wo;
    wo.predict = parse_predict_scheme(a->predict);
    report(progress, "wavelet analysis", 0.0);
    ShapeModel model = make_model(hierarchy.connectivity, hierarchy.levels.back().positions, wo);
    report(progress, "wavelet analysis", 1.0);
    lap("analysis");

    // A model that has lost its organ is refused here, before anything is written.
    const LabelFit fit = fit_to_source(hierarchy.mesh(hierarchy.connectivity.levels()), labels, a->label,
                                       !surface.dropped_component_faces.empty() && a->component == 0);
    if (!(fit.dice >= kMinLabelFitDice)) {
      const SurfaceChoices choices{mc_spacing, a->mc_spacing >= 0, a->faces > 0 || a->levels > 0,
                                   surface.closing_radius};
      if (!a->allow_poor_fit)
        throw AlgorithmError(poor_fit_message(fit, scale, choices) + ", or give --allow-poor-fit to keep it");
      warn(poor_fit_message(fit, scale, choices));
    }
    lap("label_fit");

    const double reference_margin_mm =
        a->reference_margin_mm >= 0 ? a->reference_margin_mm : default_reference_margin(scale);
    std::optional<ProfileAlignmentReport> alignment;
    if (!a->image.empty()) {
      report(progress, "appearance", 0.0);
      const Volume reference = read_volume(a->image);
      AppearanceOptions appearance;
      appearance.alignment = parse_profile_alignment(a->profile_alignment);
      alignment = add_appearance(model, reference, appearance);
      ReferenceImageOptions ro;
      ro.margin_mm = reference_margin_mm;
      add_reference_image(model, reference, ro);
      lap("appearance");
    }

    model.source_image = a->labels;
    model.source_label = a->label;
    if (a->component > 0) model.source_component = a->component;
    PhysicalFrame frame;
    frame.size = labels.size;
    frame.spacing = labels.spacing;
    frame.origin = labels.origin;
    frame.direction = labels.direction;
    model.physical_frame = frame;
    nlohmann::json quality = remesh_report(hierarchy, ro);
    const int L = hierarchy.connectivity.levels();
    quality["finest_level_quality"] = mesh_quality(hierarchy.mesh(L));
    quality["input_faces"] = surface.mesh.num_faces();
    quality["marching_cubes"] = {
        {"spacing_mm", mc_spacing}, {"smoothing_iterations", smoothing}, {"faces", surface.mesh.num_faces()}};
    model.remesh_quality = quality;
    model.scale =
        scale_record(scale, mc_spacing, smoothing, static_cast<int>(hierarchy.connectivity.faces.back().rows()),
                     a->image.empty() ? std::nullopt : std::optional<double>(reference_margin_mm), fit);
    // The manifest records every stage up to the write; the write's own time is printed.
    model.timings = timings;

    // report.html goes into the model folder with the rest, inside the same atomic write.
    std::optional<RemeshResult> unrelaxed;
    if (a->compare_unrelaxed) {
      RemeshOptions plain = ro;
      plain.relax = RelaxMode::none;
      plain.compute_stats = false;
      plain.keep_input_locator = false;
      unrelaxed = remesh(surface.mesh, plain);
    }
    report(progress, "report.html", 0.0);
    mrsnake::reports::RemeshPageOptions page;
    page.title = "mrsnake build-model " + std::filesystem::path(a->output).filename().string();
    page.input = &surface.mesh;
    // The report page measures every level against the input: remesh() built that tree on the
    // other core while the map was solved.
    page.input_locator = hierarchy.input_locator.get();
    page.unrelaxed = unrelaxed ? &*unrelaxed : nullptr;
    page.report = quality;
    page.report["input"] = a->labels + " (label " + std::to_string(a->label) + ")";
    page.timings = timings;
    const std::string html = mrsnake::reports::remesh_report_html(hierarchy, page);
    report(progress, "report.html", 1.0);
    lap("report");
    save_model(a->output, model, progress, [&html](const std::string& temp_folder) {
      write_text_file_atomically((std::filesystem::path(temp_folder) / "report.html").string(), html);
    });
    lap("write");
    const double total = std::chrono::duration<double>(clock::now() - t_start).count();

    nlohmann::json stages = nlohmann::json::array();
    for (const auto& [stage, seconds] : timings) stages.push_back({{"stage", stage}, {"seconds", seconds}});
    nlohmann::json stats = nlohmann::json::array();
    for (const DetailStats& s : model.detail_stats)
      stats.push_back({{"level", s.level},
                       {"count", s.count},
                       {"rms", s.rms},
                       {"max", s.max},
                       {"energy", s.energy},
                       {"degenerate_frames", s.degenerate_frames}});
    const auto& conn = hierarchy.connectivity;
    if (a->json) {
      print_json({{"model", a->output},
                  {"levels", L},
                  {"vertex_counts", conn.vertex_counts},
                  {"faces", conn.faces.back().rows()},
                  {"input_faces", surface.mesh.num_faces()},
                  {"mc_spacing_mm", mc_spacing},
                  {"scale", model.scale},
                  {"closing_radius_voxels", surface.closing_radius},
                  {"finest_level_quality", quality["finest_level_quality"]},
                  {"detail_stats", stats},
                  {"profile_alignment", alignment ? nlohmann::json(*alignment) : nlohmann::json()},
                  {"timings", stages},
                  {"total_seconds", total}});
      return;
    }
    std::cout << a->output << ": " << L << " levels, " << conn.vertex_counts.back() << " vertices and "
              << conn.faces.back().rows() << " faces at the finest level (input surface: " << surface.mesh.num_faces()
              << " faces)\n";
    std::printf(
        "  structure %.4g mm3 (equivalent radius %.3g mm); finest level against the label: Dice %.4f, "
        "volume %+.1f %%\n",
        scale.volume_mm3, scale.equivalent_radius_mm, fit.dice, 100.0 * (fit.volume_ratio - 1.0));
    if (alignment)
      std::printf(
          "  profiles centred on the %s (step residual %.3f; %d level%s moved, mean shift %+.3f mm, mean "
          "|shift| %.3f mm)\n",
          alignment->to_edges ? "image's edges" : "label's surface", alignment->step_residual,
          alignment->levels_aligned, alignment->levels_aligned == 1 ? "" : "s", alignment->mean_shift_mm,
          alignment->mean_abs_shift_mm);
    std::cout << "  level  detail rms (mm)  detail max (mm)\n";
    for (const DetailStats& s : model.detail_stats) std::printf("  %5d  %15.4g  %15.4g\n", s.level, s.rms, s.max);
    std::fflush(stdout);
    std::cout << "  seconds:";
    for (const auto& [stage, seconds] : timings) {
      char buf[64];
      std::snprintf(buf, sizeof buf, " %s %.3f", stage.c_str(), seconds);
      std::cout << buf;
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3f", total);
    std::cout << "; total " << buf << '\n';
  });
}

}  // namespace mrsnake::cli
