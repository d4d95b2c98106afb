// mrsnake build-model --labels IMG --label N -o MODEL: marching cubes, semi-regular
// remeshing and wavelet analysis, written as a model folder (model/model_io.h).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <vector>
#include <memory>
#include <optional>

#include "apps/cli.h"
#include "apps/slicer_module.h"
#include "apps/report/remesh_page.h"
#include "mesh/atomic_file.h"
#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/json_options.h"
#include "model/build_model.h"
#include "model/build_model_set.h"
#include "model/label_names.h"
#include "model/model_set.h"
#include "apps/report/html.h"
#include "model/build_model_json.h"
#include "model/model_io.h"

namespace mrsnake::cli {

namespace {
// What the user chose of the options that shape the surface, for the poor-fit message.
struct SurfaceChoices {
  double mc_spacing = 0;
  bool spacing_given = false, faces_given = false;
  int closing_radius = 0;  // the tunnel closing applied, in voxels (0: none)
};

// What to type about a model that lost its organ, after the library's account of the fit.
std::string poor_fit_cause(const StructureScale& scale, const SurfaceChoices& c) {
  if (c.closing_radius > 0)
    return "; closing the label's tunnels (radius " + std::to_string(c.closing_radius) +
           " voxels) changed its shape: fill the tunnels in the label volume, or give --close-tunnels 0 to see them";
  if (c.mc_spacing > 0 && c.spacing_given) {
    char text[200];
    std::snprintf(text, sizeof text,
                  "; the marching-cubes spacing %.3g mm is coarse for a structure of radius %.3g mm: "
                  "give a smaller surface.mc_spacing_mm with --config (e.g. %.3g)",
                  c.mc_spacing, scale.equivalent_radius_mm, scale.finest_voxel_mm);
    return text;
  }
  std::string cause = "; the label may be too thin or ragged for a closed genus-0 model: check it with 'mrsnake mc'";
  if (!c.spacing_given) cause += ", try surface.mc_spacing_mm 0 with --config";
  if (!c.faces_given) cause += ", or more --faces";
  return cause;
}

// The command's arguments: the options file, and the flags that override it.
struct BuildModelArgs {
  std::string labels, image, output, config, label = "1", label_names, labels_series, image_series;
  std::optional<int> faces, component, close_tunnels;
  bool allow_poor_fit = false, json = false;
};

// The file's options (or the preset), then the flags given.
BuildModelOptions options_of(const BuildModelArgs& a) {
  BuildModelOptions o = a.config.empty() ? BuildModelOptions{} : read_options_file<BuildModelOptions>(a.config);
  if (a.faces) {
    o.faces = *a.faces;
    o.levels = 0;
  }
  if (a.component) o.component = *a.component;
  if (a.close_tunnels) o.surface.close_tunnels = *a.close_tunnels;
  if (a.allow_poor_fit) o.allow_poor_fit = true;
  validate(o);
  return o;
}

SurfaceChoices choices_of(const BuildModelOptions& o, double mc_spacing, int closing_radius) {
  return {mc_spacing, o.surface.mc_spacing_mm >= 0, o.faces > 0 || o.levels > 0, closing_radius};
}

// The library's models, with the command's hints on what to type when one is refused.
BuiltModelSet build_with_hints(const Volume& labels, const Volume* image, const LabelSelection& selection,
                               const std::map<int, LabelName>& names, const BuildModelOptions& o,
                               const ProgressFn& progress) {
  const auto announce = [](int value, const std::string& name, int index, int count) {
    if (count > 1)
      info("[" + std::to_string(index + 1) + "/" + std::to_string(count) + "] label " + std::to_string(value) + " (" +
           name + ")");
  };
  try {
    return build_model_set(labels, image, selection, names, o, progress, announce);
  } catch (const LabelGenusError& e) {
    throw TopologyError(std::string(e.what()) +
                        (o.surface.close_tunnels > 0
                             ? ": try a larger --close-tunnels"
                             : "; drop --close-tunnels 0 (the default closes them up to 3 voxels)") +
                        ", or fill them in the label volume");
  } catch (const PoorFitError& e) {
    throw AlgorithmError(e.what() + poor_fit_cause(e.scale, choices_of(o, e.mc_spacing_mm, e.closing_radius)) +
                         ", or give --allow-poor-fit to keep it");
  }
}

// What the user should know of the surface: parts dropped, tunnels closed, a finest level that
// crosses itself, a poor fit kept.
void warn_about(const BuiltModel& built, const BuildModelOptions& o, int value) {
  const LabelSurface& s = built.surface;
  if (!s.dropped_component_faces.empty())
    warn("label " + std::to_string(value) + " has " + std::to_string(s.components_found) +
         " connected surfaces; the model uses the largest" +
         (o.component > 0 ? std::string() : std::string(" (--component K models the K-th largest part of the label)")));
  if (s.closing_radius > 0)
    warn("label " + std::to_string(value) + " had a genus-" + std::to_string(s.genus_before_repair) +
         " surface; closed its tunnels with a radius of " + std::to_string(s.closing_radius) + " voxels");
  if (built.self_intersections > 0)
    warn("label " + std::to_string(value) + ": the model's finest level passes through itself at " +
         std::to_string(built.self_intersections) +
         " face pairs (model.json remesh_quality): segmentations with it may fold there too");
  if (!(built.fit.dice >= kMinLabelFitDice))
    warn(describe_poor_fit(built.fit) +
         poor_fit_cause(built.scale, choices_of(o, built.mc_spacing_mm, s.closing_radius)));
}

// report.html: every level against the input, and the unrelaxed hierarchy when asked for.
std::string report_page(const BuildModelArgs& a, const BuiltStructure& structure, const ProgressFn& progress) {
  const BuiltModel& built = structure.built;
  report(progress, "report.html", 0.0);
  mrsnake::reports::RemeshPageOptions page;
  page.title = "mrsnake build-model " + std::filesystem::path(a.output).filename().string();
  page.input = &built.surface.mesh;
  // remesh() built the input's distance tree on the other core while the map was solved.
  page.input_locator = built.hierarchy.input_locator.get();
  page.unrelaxed = built.unrelaxed ? &*built.unrelaxed : nullptr;
  page.report = built.model.remesh_quality;
  page.report["input"] = a.labels + " (label " + std::to_string(structure.value) + ", " + structure.label.name + ")";
  page.timings = built.timings;
  const std::string html = mrsnake::reports::remesh_report_html(built.hierarchy, page);
  report(progress, "report.html", 1.0);
  return html;
}

nlohmann::json summary_json(const BuildModelArgs& a, const BuiltModel& built, double total_seconds) {
  const ShapeModel& model = built.model;
  const auto& conn = built.hierarchy.connectivity;
  nlohmann::json stages = nlohmann::json::array();
  for (const auto& [stage, seconds] : built.timings) stages.push_back({{"stage", stage}, {"seconds", seconds}});
  nlohmann::json stats = nlohmann::json::array();
  for (const DetailStats& s : model.detail_stats)
    stats.push_back({{"level", s.level},
                     {"count", s.count},
                     {"rms", s.rms},
                     {"max", s.max},
                     {"energy", s.energy},
                     {"degenerate_frames", s.degenerate_frames}});
  return {{"model", a.output},
          {"levels", conn.levels()},
          {"vertex_counts", conn.vertex_counts},
          {"faces", conn.faces.back().rows()},
          {"input_faces", built.surface.mesh.num_faces()},
          {"mc_spacing_mm", built.mc_spacing_mm},
          {"scale", model.scale},
          {"closing_radius_voxels", built.surface.closing_radius},
          {"spur_voxels_removed", built.surface.spur_voxels_removed},
          {"finest_level_quality", model.remesh_quality["finest_level_quality"]},
          {"finest_level_self_intersections", built.self_intersections},
          {"detail_stats", stats},
          {"profile_alignment", built.alignment ? nlohmann::json(*built.alignment) : nlohmann::json()},
          {"timings", stages},
          {"options", model.build_options},
          {"total_seconds", total_seconds}};
}

void print_summary(const BuildModelArgs& a, const BuiltModel& built, double total_seconds) {
  const auto& conn = built.hierarchy.connectivity;
  std::cout << a.output << ": " << conn.levels() << " levels, " << conn.vertex_counts.back() << " vertices and "
            << conn.faces.back().rows()
            << " faces at the finest level (input surface: " << built.surface.mesh.num_faces() << " faces)\n";
  std::printf(
      "  structure %.4g mm3 (equivalent radius %.3g mm); finest level against the label: Dice %.4f, "
      "volume %+.1f %%\n",
      built.scale.volume_mm3, built.scale.equivalent_radius_mm, built.fit.dice, 100.0 * (built.fit.volume_ratio - 1.0));
  if (const auto& al = built.alignment)
    std::printf(
        "  profiles centred on the %s (step residual %.3f; %d level%s moved, mean shift %+.3f mm, mean "
        "|shift| %.3f mm)\n",
        al->to_edges ? "image's edges" : "label's surface", al->step_residual, al->levels_aligned,
        al->levels_aligned == 1 ? "" : "s", al->mean_shift_mm, al->mean_abs_shift_mm);
  std::cout << "  level  detail rms (mm)  detail max (mm)\n";
  for (const DetailStats& s : built.model.detail_stats) std::printf("  %5d  %15.4g  %15.4g\n", s.level, s.rms, s.max);
  std::fflush(stdout);
  std::cout << "  seconds:";
  for (const auto& [stage, seconds] : built.timings) {
    char buf[64];
    std::snprintf(buf, sizeof buf, " %s %.3f", stage.c_str(), seconds);
    std::cout << buf;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", total_seconds);
  std::cout << "; total " << buf << '\n';
}

double seconds_since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

// The page of a model of several structures: one row per structure and per skipped label;
// each structure's own page is structures/<value>/report.html.
std::string index_page(const BuildModelArgs& a, const BuiltModelSet& set) {
  mrsnake::reports::HtmlPage page("mrsnake build-model " + std::filesystem::path(a.output).filename().string());
  page.paragraph("From " + a.labels + (a.image.empty() ? std::string() : " and the image " + a.image) + ": " +
                 std::to_string(set.structures.size()) + " structures, " + std::to_string(set.skipped.size()) +
                 " labels skipped. Each structure's remeshing report is structures/VALUE/report.html.");
  std::vector<std::vector<std::string>> rows;
  char text[64];
  for (const BuiltStructure& s : set.structures) {
    const auto& conn = s.built.hierarchy.connectivity;
    std::vector<std::string> row{std::to_string(s.value), s.label.name, std::to_string(conn.levels()),
                                 std::to_string(conn.faces.back().rows())};
    std::snprintf(text, sizeof text, "%.4g", s.built.scale.volume_mm3);
    row.emplace_back(text);
    std::snprintf(text, sizeof text, "%.4f", s.built.fit.dice);
    row.emplace_back(text);
    row.push_back("structures/" + std::to_string(s.value) + "/report.html");
    rows.push_back(std::move(row));
  }
  page.heading("Structures");
  page.table({"value", "name", "levels", "faces", "volume mm3", "fit Dice", "its page"}, rows);
  if (!set.skipped.empty()) {
    std::vector<std::vector<std::string>> skipped;
    for (const SkippedLabel& k : set.skipped) skipped.push_back({std::to_string(k.value), k.name, k.reason});
    page.heading("Skipped labels");
    page.table({"value", "name", "reason"}, skipped);
  }
  return page.str();
}

nlohmann::json set_summary_json(const BuildModelArgs& a, const BuiltModelSet& set, double total_seconds) {
  nlohmann::json structures = nlohmann::json::array();
  for (const BuiltStructure& s : set.structures) {
    nlohmann::json j = summary_json(a, s.built, 0.0);
    j.erase("total_seconds");
    j["value"] = s.value;
    j["name"] = s.label.name;
    structures.push_back(std::move(j));
  }
  nlohmann::json skipped = nlohmann::json::array();
  for (const SkippedLabel& k : set.skipped)
    skipped.push_back({{"value", k.value}, {"name", k.name}, {"reason", k.reason}});
  return {
      {"model", a.output},
      {"structures", structures},
      {"skipped", skipped},
      {"reference_margin_mm", set.reference_image.empty() ? nlohmann::json() : nlohmann::json(set.reference_margin_mm)},
      {"total_seconds", total_seconds}};
}

void print_set_summary(const BuildModelArgs& a, const BuiltModelSet& set, double total_seconds) {
  std::cout << a.output << ": " << set.structures.size() << " structures";
  if (!set.skipped.empty()) std::cout << ", " << set.skipped.size() << " labels skipped";
  std::cout << "\n  value  levels      faces   fit Dice  name\n";
  for (const BuiltStructure& s : set.structures)
    std::printf("  %5d %7d %10ld   %8.4f  %s\n", s.value, s.built.hierarchy.connectivity.levels(),
                static_cast<long>(s.built.hierarchy.connectivity.faces.back().rows()), s.built.fit.dice,
                s.label.name.c_str());
  std::printf("  total %.3f s\n", total_seconds);
  std::fflush(stdout);
}

// Each structure's page into its folder, and the index (or, for one structure, its page) on top.
void write_pages(const BuildModelArgs& a, const BuiltModelSet& set, const std::vector<std::string>& pages,
                 const std::string& temp_folder) {
  const std::filesystem::path temp(temp_folder);
  if (set.structures.size() == 1) {
    write_text_file_atomically((temp / "report.html").string(), pages[0]);
    return;
  }
  for (std::size_t i = 0; i < set.structures.size(); ++i)
    write_text_file_atomically((temp / "structures" / std::to_string(set.structures[i].value) / "report.html").string(),
                               pages[i]);
  write_text_file_atomically((temp / "report.html").string(), index_page(a, set));
}

// Read, build, write the model folder with its report pages, and print what was done.
void run_build_model(const BuildModelArgs& a) {
  const auto t_start = std::chrono::steady_clock::now();
  const auto progress = terminal_progress();
  const BuildModelOptions options = options_of(a);
  const LabelSelection selection = parse_label_selection(a.label);
  if (options.component > 0 && (selection.all || selection.values.size() > 1))
    throw OptionsError("--component models a part of one label; give one --label value with it");
  const std::map<int, LabelName> names =
      a.label_names.empty() ? std::map<int, LabelName>{} : read_label_names(a.label_names);
  report(progress, "reading " + a.labels, 0.0);
  const Volume labels = read_volume(a.labels, a.labels_series);
  const std::optional<Volume> image =
      a.image.empty() ? std::nullopt : std::optional<Volume>(read_volume(a.image, a.image_series));
  const double read_seconds = seconds_since(t_start);

  BuiltModelSet set = build_with_hints(labels, image ? &*image : nullptr, selection, names, options, progress);
  for (const SkippedLabel& k : set.skipped)
    warn("skipped label " + std::to_string(k.value) + " (" + k.name + "): " + k.reason);
  std::vector<std::string> pages;
  for (BuiltStructure& s : set.structures) {
    warn_about(s.built, options, s.value);
    s.built.model.source_image = a.labels;
    // The manifest records every stage up to the write; the write's own time is printed.
    s.built.timings.insert(s.built.timings.begin(), {"read", read_seconds});
    s.built.model.timings = s.built.timings;
    const auto t = std::chrono::steady_clock::now();
    pages.push_back(report_page(a, s, progress));
    s.built.timings.emplace_back("report", seconds_since(t));
  }
  // The pages go into the model folder with the rest, inside the same atomic write.
  const auto t = std::chrono::steady_clock::now();
  save_model_set(a.output, set.model_set(a.labels), progress,
                 [&](const std::string& temp_folder) { write_pages(a, set, pages, temp_folder); });
  const double write_seconds = seconds_since(t);
  for (BuiltStructure& s : set.structures) s.built.timings.emplace_back("write", write_seconds);
  const double total = seconds_since(t_start);
  const bool one = set.structures.size() == 1 && !selection.all;
  if (a.json)
    print_json(one ? summary_json(a, set.structures[0].built, total) : set_summary_json(a, set, total));
  else if (one)
    print_summary(a, set.structures[0].built, total);
  else
    print_set_summary(a, set, total);
}

}  // namespace

void add_build_model_command(CLI::App& app) {
  auto* cmd =
      app.add_subcommand("build-model",
                         "Build a multiresolution shape model of one or more labels of a label image: marching cubes, "
                         "semi-regular remeshing, lifting-wavelet analysis");
  auto a = std::make_shared<BuildModelArgs>();
  cmd->add_option("--labels", a->labels, "Label volume (.nii .nii.gz .nrrd .mha .mhd .gipl, or a DICOM folder)");
  cmd->add_option("--label", a->label,
                  "Label values of the structures, e.g. 5 or 1,3,7,8, or all: every label whose surface is closed "
                  "genus 0 (after --close-tunnels), the others skipped with their reason; one model folder holds them")
      ->required();
  cmd->add_option("--label-names", a->label_names,
                  "Names (and colours) of the labels: an ITK-SNAP label description file, or a CSV of value,name rows; "
                  "kept in the model and written into the segmentation's outputs (default: 'label N')")
      ->check(CLI::ExistingFile);
  cmd->add_option("--image", a->image,
                  "Reference intensity image of the labels (same physical space): stores the appearance "
                  "(profiles along the normals, inside/outside statistics) that 'mrsnake segment' matches, and a "
                  "crop of the image around the organ that 'mrsnake segment --init register' registers to a new image");
  cmd->add_option("--labels-series", a->labels_series,
                  "The DICOM series of the --labels folder when it holds several: its Series Instance UID");
  cmd->add_option("--image-series", a->image_series,
                  "The DICOM series of the --image folder when it holds several: its Series Instance UID");
  cmd->add_option("-o,--output", a->output, "Output model folder (replaced if it is already a model)")->required();
  cmd->add_option("--faces", a->faces,
                  "Wanted face count of the finest level (default: triangles with edges of half the surface's "
                  "sampling length, the marching-cubes spacing or the finest voxel, 1024 to 32768)")
      ->check(CLI::Range(16, 50000000));
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
  cmd->add_flag("--allow-poor-fit", a->allow_poor_fit,
                "Write the model even when its finest level, rasterized on the label's grid, has a Dice below 0.90 "
                "against the label (otherwise refused with exit code 5)");
  cmd->add_option("--config", a->config,
                  "Options from a JSON file (the form of model.json's \"build_options\"; keys left out keep the "
                  "preset's values; docs/commands/build-model.md lists them); the flags given override it")
      ->check(CLI::ExistingFile);
  cmd->add_flag_callback(
         "--print-config",
         [] {
           print_json(nlohmann::json(BuildModelOptions{}));
           throw CLI::Success();
         },
         "Print the preset's options as JSON (a start for --config) and exit")
      ->trigger_on_parse();
  cmd->add_flag("--json", a->json, "Print a JSON summary");
  cmd->footer(
      "Example: mrsnake build-model --labels liver-labels.nii.gz --label 255 --image liver.nii.gz -o liver.model "
      "--faces 32768\n"
      "Every default length follows the structure's size and voxels (model.json 'scale' records them). A label\n"
      "with tunnels of up to 3 voxels (genus > 0) is closed by default, e.g. the liver of abdomen-ct-small-seg.nii.gz\n"
      "(label 5); wider ones need a larger --close-tunnels.\n"
      "Build again exactly: mrsnake build-model ... --config <(jq .build_options MODEL/model.json)");
  // As a 3D Slicer CLI module (docs/slicer.md): the reference labels and image positionally.
  auto positional = std::make_shared<std::pair<std::string, std::string>>();
  cmd->add_option("LABELS", positional->first, "The label volume, as a positional argument (instead of --labels)");
  cmd->add_option("IMAGE", positional->second, "The reference image, as a positional argument (instead of --image)");
  cmd->add_flag_callback(
      "--xml",
      [] {
        std::cout << build_model_module_xml();
        throw CLI::Success();
      },
      "Print the 3D Slicer CLI module description (Slicer Execution Model XML) and exit");
  cmd->callback([a, positional] {
    if (a->labels.empty() == positional->first.empty())
      throw CLI::ValidationError("--labels", "give the label volume once: --labels LABELS, or LABELS first");
    if (!positional->second.empty() && !a->image.empty())
      throw CLI::ValidationError("--image", "give the reference image once: --image IMAGE, or IMAGE second");
    if (a->labels.empty()) a->labels = positional->first;
    if (a->image.empty()) a->image = positional->second;
    run_build_model(*a);
  });
}

}  // namespace mrsnake::cli
