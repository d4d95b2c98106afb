// mrsnake mc: the surface of one label of a label volume, in physical coordinates.
#include <iostream>

#include "apps/cli.h"
#include "mesh/image_io.h"
#include "mesh/label_repair.h"
#include "mesh/marching_cubes.h"
#include "mesh/mesh_io.h"
#include "mesh/topology.h"

namespace mrsnake::cli {

void add_mc_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("mc", "Extract one label's surface with marching cubes (discrete flying edges)");
  struct Args {
    std::string labels, output;
    int label = 1;
    int smooth = 0;
    int close_tunnels = 0;
    int component = 0;
    double spacing = 0;
    bool remove_spurs = false;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  cmd->add_option("--labels", a->labels, "Label volume (.nii .nii.gz .nrrd .mha .mhd .gipl, or a DICOM folder)")
      ->required();
  cmd->add_option("--label", a->label, "Label value to extract")->required();
  cmd->add_option("-o,--output", a->output, "Output mesh (.vtp .vtk .stl .ply .obj .off)")->required();
  cmd->add_option("--smooth", a->smooth, "Windowed-sinc smoothing iterations (volume-preserving); 0 = none")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--close-tunnels", a->close_tunnels,
                  "If the surface is not genus 0, close the label with radii up to this many voxels until it is")
      ->check(CLI::Range(0, 20));
  cmd->add_option("--component", a->component,
                  "Only the label's K-th largest connected part (1 = the largest; as 'build-model --component'); "
                  "0 = all of it, of which the largest surface is kept")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--spacing", a->spacing,
                  "Extract the 0.5 isosurface of the label's Gaussian-smoothed occupancy resampled to this isotropic "
                  "spacing in mm (as build-model's surface.mc_spacing_mm); 0 = the voxels' own surface (default)")
      ->check(CLI::Range(0.0, 100.0));
  cmd->add_flag("--remove-spurs", a->remove_spurs,
                "First remove the label's spurs, voxels hanging by at most one face, again until none is left (a line "
                "of voxels one voxel wide, which --smooth turns into a needle); as build-model does");
  cmd->add_flag("--json", a->json, "Print a JSON summary");
  cmd->footer(
      "Example: mrsnake mc --labels liver-labels.nii.gz --label 255 --smooth 20 -o liver.vtp\n"
      "The surface build-model uses by default: mrsnake mc --labels liver-labels.nii.gz --label 255 --spacing 1.2 "
      "--smooth 5 -o liver-1.2mm.vtp");
  cmd->callback([a] {
    const auto progress = terminal_progress();
    report(progress, "reading " + a->labels, 0.0);
    const Volume labels =
        a->component > 0 ? keep_label_part(read_volume(a->labels), a->label, a->component) : read_volume(a->labels);
    LabelSurfaceOptions options;
    options.smoothing_iterations = a->smooth;
    options.max_closing_radius = a->close_tunnels;
    options.resample_spacing_mm = a->spacing;
    options.remove_spurs = a->remove_spurs;
    const LabelSurface surface = extract_label_surface(labels, a->label, options, progress);
    if (!surface.dropped_component_faces.empty()) {
      // Components are sorted largest first: the first few sizes say enough.
      const auto& dropped = surface.dropped_component_faces;
      std::string sizes;
      for (std::size_t i = 0; i < std::min<std::size_t>(dropped.size(), 5); ++i)
        sizes += (sizes.empty() ? "" : ", ") + std::to_string(dropped[i]);
      if (dropped.size() > 5) sizes += ", ...";
      warn("label " + std::to_string(a->label) + " has " + std::to_string(surface.components_found) +
           " connected surfaces; kept the largest and dropped " +
           std::to_string(surface.dropped_component_faces.size()) + " (largest dropped, in faces: " + sizes + ")");
    }
    if (surface.closing_radius > 0)
      warn("label " + std::to_string(a->label) + " had a genus-" + std::to_string(surface.genus_before_repair) +
           " surface; closed its tunnels with a radius of " + std::to_string(surface.closing_radius) + " voxels");
    write_mesh(a->output, surface.mesh);
    const TopologyReport topo = topology_report(surface.mesh);
    const double voxel_volume = labels.spacing[0] * labels.spacing[1] * labels.spacing[2];
    std::size_t count = 0;
    for (float v : labels.data) count += v == static_cast<float>(a->label);
    if (a->json) {
      print_json({{"output", a->output},
                  {"label", a->label},
                  {"vertices", surface.mesh.num_vertices()},
                  {"faces", surface.mesh.num_faces()},
                  {"components_found", surface.components_found},
                  {"genus_before_repair", surface.genus_before_repair},
                  {"closing_radius_voxels", surface.closing_radius},
                  {"spur_voxels_removed", surface.spur_voxels_removed},
                  {"topology", topo},
                  {"enclosed_volume_mm3", enclosed_volume(surface.mesh)},
                  {"label_volume_mm3", static_cast<double>(count) * voxel_volume}});
    } else {
      std::cout << a->output << ": " << surface.mesh.num_vertices() << " vertices, " << surface.mesh.num_faces()
                << " faces, " << topo.describe() << ", enclosed volume " << enclosed_volume(surface.mesh)
                << " mm3 (label: " << static_cast<double>(count) * voxel_volume << " mm3"
                << (a->remove_spurs ? ", " + std::to_string(surface.spur_voxels_removed) + " spur voxels removed" : "")
                << ")\n";
    }
  });
}

}  // namespace mrsnake::cli
