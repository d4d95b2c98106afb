#pragma once
/// \file quality_control.h
/// A verdict on one structure's segmentation from what the run already knows, so that a
/// result nobody watches is flagged when it is probably wrong: the profile match at the end,
/// the registration, the volume and the shape against the model, the steps the snake had to
/// reject and the self-intersections it undid.
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "snake/segment.h"

namespace mrsnake {

/// The limits of a result not flagged. Every one is relative (a cost, a ratio, a fraction of
/// the structure's size), so the same limits serve any scale.
struct QualityControlOptions {
  /// The segmented volume may be this factor off the model's, either way.
  double max_volume_factor = 1.5;
  /// The mean matched cost of the last deformed level (0: a perfect match; a profile whose
  /// correlation is below 0.6 costs 0.4 or more).
  double max_profile_cost = 0.3;
  /// The shape's distance from the model: the RMS of the vertices' residual after the best
  /// similarity onto the model's finest level (same connectivity), over the model's
  /// equivalent radius.
  double max_shape_residual = 0.25;
  /// Vertices moved back to undo self-intersections, as a fraction of the finest level's.
  double max_rolled_back_fraction = 0.05;
};

/// What the verdict is made of, and the verdict.
struct QualityControl {
  double volume_ratio = 0;       ///< segmented volume / the model's finest level's
  double profile_cost = 0;       ///< mean matched cost of the last deformed level
  double shape_residual = 0;     ///< as QualityControlOptions::max_shape_residual measures it
  bool registration_used = true; ///< false: the registration was asked for and rejected
  int rejected_steps = 0;        ///< over every level
  int rolled_back_vertices = 0;  ///< over every level
  int self_intersections = -1;   ///< of the final surface (-1: not counted)
  bool suspect = false;
  std::string reason;            ///< every limit passed, "; "-joined; empty when not suspect
};

/// The verdict on `result` of `model`, whose segmented volume (as the label map holds it)
/// is `volume_mm3`. A rejected registration alone does not flag a result (its fallback
/// often succeeds); it is named in the reason of a result flagged for another cause.
/// \throw nothing.
QualityControl assess_segmentation(const SegmentResult& result, const SnakeModel& model, double volume_mm3,
                                   const QualityControlOptions& options = {});

void to_json(nlohmann::json& j, const QualityControl& qc);

}  // namespace mrsnake
