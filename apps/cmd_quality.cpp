// mrsnake quality MESH [--reference REF]: triangle quality, valence and, against a
// reference, the symmetric surface distance.
#include <cstdio>
#include <iostream>
#include <optional>

#include "apps/cli.h"
#include "mesh/distance.h"
#include "mesh/mesh_io.h"
#include "mesh/quality.h"

namespace mrsnake::cli {
namespace {

void print_row(const char* name, double value, const char* unit) {
  std::printf("  %-28s %12.6g %s\n", name, value, unit);
}

void print_quality(const std::string& path, const QualityReport& q) {
  std::printf("%s\n", path.c_str());
  std::printf("  %-28s %12d\n", "vertices", q.vertices);
  std::printf("  %-28s %12d\n", "faces", q.faces);
  print_row("min angle", q.min_angle_deg, "deg");
  print_row("mean min angle", q.mean_min_angle_deg, "deg");
  print_row("min angle < 30 deg", q.pct_min_angle_below_30, "% of faces");
  print_row("angle deviation from 60", q.angle_deviation_deg, "deg");
  print_row("angle variance", q.angle_variance_deg2, "deg^2");
  print_row("Q min (Frey-Borouchaki)", q.q_min, "");
  print_row("Q mean", q.q_mean, "");
  print_row("radius ratio min", q.radius_ratio_min, "");
  print_row("radius ratio mean", q.radius_ratio_mean, "");
  print_row("edge length mean", q.edge_length_mean, "mm");
  print_row("edge length cv", q.edge_length_cv, "");
  print_row("edge length variance", q.edge_length_variance, "(normalized)");
  print_row("valence 6 (interior)", q.pct_valence6_interior, "% of interior vertices");
  print_row("valence 4 (boundary)", q.pct_valence4_boundary, "% of boundary vertices");
  print_row("area cv", q.area_cv, "");
}

void print_distance(const std::string& reference, const SurfaceDistance& d) {
  std::printf("distance to %s (diagonal %.6g mm)\n", reference.c_str(), d.reference_diagonal_mm);
  std::printf("  %-28s %12.6g mm %10.4f %%\n", "mean", d.mean_mm, d.mean_pct);
  std::printf("  %-28s %12.6g mm %10.4f %%\n", "rms", d.rms_mm, d.rms_pct);
  std::printf("  %-28s %12.6g mm %10.4f %%\n", "hausdorff", d.hausdorff_mm, d.hausdorff_pct);
}

}  // namespace

void add_quality_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("quality",
                                 "Print a mesh's triangle quality and valence, and its distance to a reference mesh");
  auto mesh_path = std::make_shared<std::string>();
  auto reference_path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto samples = std::make_shared<int>(DistanceOptions{}.samples_per_face);
  cmd->add_option("MESH", *mesh_path, "Mesh file (.vtp .vtk .stl .ply .obj .off)")->required();
  cmd->add_option("--reference", *reference_path,
                  "Reference mesh: adds the symmetric surface distance (mean, RMS, Hausdorff)");
  cmd->add_option("--samples", *samples, "Random points per face for the distance, on top of every vertex")
      ->check(CLI::Range(0, 100000));
  cmd->add_flag("--json", *json, "Print JSON instead of text (keys: docs/report-keys.md)");
  cmd->footer("Example: mrsnake quality out/level_4.vtp --reference liver.vtp --json");
  cmd->callback([=] {
    const TriMesh mesh = read_mesh(*mesh_path);
    std::optional<TriMesh> reference;
    if (!reference_path->empty()) reference = read_mesh(*reference_path);
    const ProgressFn progress = terminal_progress();
    report(progress, "quality", 0.0);
    const QualityReport q = mesh_quality(mesh);
    report(progress, "quality", 1.0);
    std::optional<SurfaceDistance> d;
    if (reference) {
      report(progress, "surface distance", 0.0);
      DistanceOptions options;
      options.samples_per_face = *samples;
      d = surface_distance(mesh, *reference, options);
      report(progress, "surface distance", 1.0);
    }
    if (*json) {
      nlohmann::json j = q;
      j["file"] = *mesh_path;
      if (d) {
        j["distance"] = *d;
        j["distance"]["reference"] = *reference_path;
        j["distance"]["samples_per_face"] = *samples;
      }
      print_json(j);
      return;
    }
    print_quality(*mesh_path, q);
    if (d) print_distance(*reference_path, *d);
  });
}

}  // namespace mrsnake::cli
