#include "snake/label_fit.h"

#include <nlohmann/json.hpp>

#include "evaluation/evaluate.h"
#include "snake/rasterize.h"

namespace mrsnake {

LabelFit measure_label_fit(const TriMesh& surface, const Volume& labels, int label) {
  return label_fit_of_raster(rasterize_mesh(surface, labels, 1.0f), labels, label);
}

LabelFit label_fit_of_raster(const Volume& raster, const Volume& labels, int label) {
  const SegmentationScores s = evaluate_segmentation(raster, labels, 1, label);
  LabelFit f;
  f.dice = s.dice;
  f.model_volume_mm3 = s.seg_volume_mm3;
  f.label_volume_mm3 = s.truth_volume_mm3;
  f.volume_ratio = s.truth_volume_mm3 > 0 ? s.seg_volume_mm3 / s.truth_volume_mm3 : 0.0;
  return f;
}

void to_json(nlohmann::json& j, const LabelFit& f) {
  j = {{"dice", f.dice},
       {"model_volume_mm3", f.model_volume_mm3},
       {"label_volume_mm3", f.label_volume_mm3},
       {"volume_ratio", f.volume_ratio}};
}

}  // namespace mrsnake
