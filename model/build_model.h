#pragma once
/// \file build_model.h
/// The offline pipeline from a reference label volume to a shape model, as a sequence of
/// named stages: the label's surface (marching cubes), the semi-regular hierarchy
/// (remesh/remesh.h), the wavelet analysis (model/shape_model.h), the check that the model
/// still covers its label, and, with a reference image, the appearance and the reference
/// crop the segmentation registers. Every default length follows the structure's size and
/// voxels (snake/structure_scale.h); the defaults of BuildModelOptions are the preset that
/// `mrsnake build-model` runs.
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "mesh/errors.h"
#include "mesh/marching_cubes.h"
#include "mesh/progress.h"
#include "mesh/volume.h"
#include "model/shape_model.h"
#include "remesh/remesh.h"
#include "snake/appearance.h"
#include "snake/label_fit.h"
#include "snake/structure_scale.h"

namespace mrsnake {

/// The remeshing preset of a model: remesh()'s defaults, except that the vertices stay on
/// the reference surface (no surface fit) and the curvature sizing is stronger, so that the
/// snake samples the organ's bends more densely (docs/remesh.md gives the measurements).
RemeshOptions model_remesh_preset();

/// Options of the label's surface. Negative lengths and counts are derived from the structure.
struct ModelSurfaceOptions {
  /// Marching cubes on the label's Gaussian-smoothed occupancy resampled to this isotropic
  /// spacing in mm; 0 = the voxels' own surface; < 0 = default_marching_cubes_spacing().
  double mc_spacing_mm = -1;
  /// Windowed-sinc smoothing iterations; < 0 = 5 on a resampled occupancy (it has no
  /// staircase left), 20 on the voxels' surface.
  int smoothing_iterations = -1;
  /// Tunnels are closed with radii up to this many voxels until the surface is genus 0; 0 = none.
  int close_tunnels = 3;
  /// Remove the label's spurs (mesh/label_spurs.h) first: voxels hanging by at most one face,
  /// which the smoothing turns into needles that no level of the model can follow.
  bool remove_spurs = true;
};

/// What build_model() measures beyond the model, for its report page.
struct ModelReportOptions {
  bool level_stats = false;        ///< quality and distance to the input at every level (slower)
  bool compare_unrelaxed = false;  ///< also remesh without relaxation, for the comparison (a second run)
};

/// Options of build_model(); the defaults are the preset of `mrsnake build-model`.
struct BuildModelOptions {
  int label = 1;      ///< label value of the structure
  int component = 0;  ///< model only the label's k-th largest part (1 = the largest); 0 = all of it
  ModelSurfaceOptions surface;
  /// Wanted faces of the finest level; 0 = default_face_count() of the surface.
  int faces = 0;
  /// Number of levels instead of `faces` (> 0), with remesh.base_vertices base vertices.
  int levels = 0;
  RemeshOptions remesh = model_remesh_preset();
  WaveletOptions wavelet;
  AppearanceOptions appearance;
  /// Margin (mm) of the stored reference crop around the organ; < 0 = default_reference_margin().
  double reference_margin_mm = -1;
  /// Keep a model whose finest level covers its label with a Dice below kMinLabelFitDice.
  bool allow_poor_fit = false;
  ModelReportOptions report;
};

/// \throw OptionsError naming the JSON key of the first option out of its range.
void validate(const BuildModelOptions& options);

/// A model and what its stages measured on the way.
struct BuiltModel {
  ShapeModel model;                       ///< with its provenance, quality, scale and timings filled
  RemeshResult hierarchy;                 ///< the semi-regular hierarchy the model analyses
  RemeshOptions remesh;                   ///< the options it was remeshed with, resolution included
  std::optional<RemeshResult> unrelaxed;  ///< with report.compare_unrelaxed
  LabelSurface surface;                   ///< the marching-cubes surface it remeshes
  StructureScale scale;                   ///< the structure's size
  LabelFit fit;                           ///< the finest level against the label
  int self_intersections = 0;             ///< face pairs of the finest level that cross (0 for a valid surface)
  double mc_spacing_mm = 0;
  int smoothing_iterations = 0;
  std::optional<double> reference_margin_mm;            ///< with an image
  std::optional<ProfileAlignmentReport> alignment;      ///< with an image
  std::vector<std::pair<std::string, double>> timings;  ///< seconds per stage, in order
};

/// The label's surface is not genus 0, and the allowed closing did not make it so.
class LabelGenusError : public TopologyError {
 public:
  LabelGenusError(const std::string& what, int genus) : TopologyError(what), genus(genus) {}
  int genus;
};

/// The finest level covers its label with a Dice below kMinLabelFitDice.
class PoorFitError : public AlgorithmError {
 public:
  PoorFitError(const std::string& what, const BuiltModel& built)
      : AlgorithmError(what),
        fit(built.fit),
        scale(built.scale),
        mc_spacing_mm(built.mc_spacing_mm),
        closing_radius(built.surface.closing_radius) {}
  LabelFit fit;
  StructureScale scale;
  double mc_spacing_mm;
  int closing_radius;  ///< the tunnel closing applied, in voxels (0: none)
};

/// "the model's finest level covers its label with Dice ... below the ... accepted": what
/// PoorFitError says.
std::string describe_poor_fit(const LabelFit& fit);

/// A model of one label of `labels`, with the appearance of `image` when it is given.
/// \pre image, when given, lies in the physical space of labels.
/// \throw OptionsError if the options are out of range (validate).
/// \throw InputError if the label is absent or the image constant; LabelGenusError; the
///        errors of remesh(); PoorFitError unless options.allow_poor_fit.
BuiltModel build_model(const Volume& labels, const Volume* image, const BuildModelOptions& options = {},
                       const ProgressFn& progress = {});

}  // namespace mrsnake
