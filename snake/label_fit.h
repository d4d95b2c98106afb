#pragma once
/// \file label_fit.h
/// How well a model's finest level reproduces the label it was built from: the level is
/// rasterized on the label's own grid and scored against it. A model that has lost its organ
/// (a surface too coarse for the structure) is caught here, before anything is segmented.
#include <nlohmann/json_fwd.hpp>

#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake {

/// The finest level against its label, on the label's grid.
struct LabelFit {
  double dice = 0;
  double model_volume_mm3 = 0;  ///< of the rasterized level
  double label_volume_mm3 = 0;
  double volume_ratio = 0;  ///< model / label
};

/// Rasterizes `surface` (closed, in the labels' physical space) on the grid of `labels` and
/// scores it against the voxels equal to `label`.
/// \pre surface is closed; labels has data of its size.
/// \throw nothing beyond std::bad_alloc.
LabelFit measure_label_fit(const TriMesh& surface, const Volume& labels, int label);

/// The same score from a surface already rasterized on the labels' grid (1 inside), so that
/// one rasterization serves several references.
/// \pre raster has the grid of labels.
/// \throw nothing beyond std::bad_alloc.
LabelFit label_fit_of_raster(const Volume& raster, const Volume& labels, int label);

/// The smallest Dice build-model accepts without --allow-poor-fit.
constexpr double kMinLabelFitDice = 0.90;

/// Keys: dice, model_volume_mm3, label_volume_mm3, volume_ratio.
void to_json(nlohmann::json& j, const LabelFit& f);

}  // namespace mrsnake
