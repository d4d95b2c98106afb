// mrsnake evaluate: scores a segmentation against a truth (see evaluation/evaluate.h).
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "apps/cli.h"
#include "mesh/distance.h"
#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/mesh_io.h"
#include "evaluation/evaluate.h"

namespace mrsnake::cli {

void add_evaluate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "evaluate", "Score a segmentation against a truth: Dice, Jaccard, volume difference, ASSD, HD95, Hausdorff");
  struct Args {
    std::string seg, truth, seg_mesh, truth_mesh;
    int label = 1;
    bool json = false;
  };
  auto a = std::make_shared<Args>();
  auto* seg = cmd->add_option("--seg", a->seg, "Segmentation label volume");
  auto* truth = cmd->add_option("--truth", a->truth, "Truth label volume, on the same grid");
  cmd->add_option("--label", a->label, "The label scored in both volumes")->capture_default_str();
  auto* seg_mesh = cmd->add_option("--seg-mesh", a->seg_mesh, "Segmented surface: adds surface-to-surface distances");
  auto* truth_mesh = cmd->add_option("--truth-mesh", a->truth_mesh, "Truth surface (with --seg-mesh)");
  seg->needs(truth);
  truth->needs(seg);
  seg_mesh->needs(truth_mesh);
  truth_mesh->needs(seg_mesh);
  cmd->add_flag("--json", a->json, "Print JSON instead of text");
  cmd->footer(
      "Surface distances are measured in mm between the centres of boundary voxels (object voxels with a\n"
      "6-neighbour outside); both directions are pooled: ASSD = mean, HD95 = 95th percentile (nearest rank),\n"
      "Hausdorff = maximum. Volume difference = (V_seg - V_truth) / V_truth * 100.\n"
      "Examples:\n"
      "  mrsnake evaluate --seg result.nii.gz --truth case7/truth.nii.gz --json\n"
      "  mrsnake evaluate --seg-mesh result.vtp --truth-mesh case7/truth.vtp");
  cmd->callback([cmd, a] {
    if (a->seg.empty() && a->seg_mesh.empty())
      throw CLI::ValidationError(
          "evaluate", "give --seg and --truth (volumes), or --seg-mesh and --truth-mesh (surfaces), or both");
    nlohmann::json j = nlohmann::json::object();
    SegmentationScores scores;
    SurfaceDistance surface;
    if (!a->seg.empty()) {
      const Volume s = read_volume(a->seg);
      const Volume t = read_volume(a->truth);
      require_same_grid(s, t, "'" + a->seg + "'", "'" + a->truth + "'");
      scores = evaluate_segmentation(s, t, a->label, a->label);
      j = scores;
      j["label"] = a->label;
    }
    if (!a->seg_mesh.empty()) {
      const TriMesh sm = read_mesh(a->seg_mesh), tm = read_mesh(a->truth_mesh);
      surface = surface_distance(sm, tm);
      j["surface_distance"] = surface;
    }
    if (a->json) {
      print_json(j);
      return;
    }
    std::cout << std::fixed;
    auto mm = [](double x) {
      std::ostringstream s;
      s << std::fixed << std::setprecision(3);
      if (std::isfinite(x))
        s << x << " mm";
      else
        s << "inf (the segmentation is empty)";
      return s.str();
    };
    if (!a->seg.empty())
      std::cout << std::setprecision(4) << "dice                 " << scores.dice << '\n'
                << "jaccard              " << scores.jaccard << '\n'
                << std::setprecision(2) << "volume difference    " << scores.volume_difference_pct << " % ("
                << scores.seg_volume_mm3 << " vs " << scores.truth_volume_mm3 << " mm3)\n"
                << "assd                 " << mm(scores.assd_mm) << '\n'
                << "hd95                 " << mm(scores.hd95_mm) << '\n'
                << "hausdorff            " << mm(scores.hausdorff_mm) << '\n';
    if (!a->seg_mesh.empty())
      std::cout << std::setprecision(3) << "surface mean         " << surface.mean_mm << " mm (" << surface.mean_pct
                << " % of the truth's bounding-box diagonal)\n"
                << "surface rms          " << surface.rms_mm << " mm\n"
                << "surface hausdorff    " << surface.hausdorff_mm << " mm (" << surface.hausdorff_pct << " %)\n";
    (void)cmd;
  });
}

}  // namespace mrsnake::cli
