#pragma once
/// \file quality_control.h
/// A verdict on one structure's segmentation from what the run already knows, so that a
/// result nobody watches is flagged when it is probably wrong: the match at the end against chance,
/// the registration, the volume and the shape against the model, the steps the snake had to
/// reject and the self-intersections it undid.
#include <optional>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "snake/segment.h"

namespace mrsnake {

/// The limits of a result not flagged. Every one is relative (a cost, a ratio, a fraction of
/// the structure's size), so the same limits serve any scale.
struct QualityControlOptions {
  /// The segmented volume may be this factor off the model's, either way.
  double max_volume_factor = 1.5;
  /// The final surface's match over the chance match (SegmentResult::final_match_cost over
  /// chance_match_cost): 1 is a result that matches the image no better than where the
  /// structure is not.
  double max_match_ratio = 0.75;
  /// The shape's distance from the model: the RMS of the vertices' residual after the best
  /// similarity onto the model's finest level (same connectivity), over the model's
  /// equivalent radius.
  double max_shape_residual = 0.25;
  /// Vertices moved back to undo self-intersections, as a fraction of the finest level's.
  double max_rolled_back_fraction = 0.05;
  /// Two weaker signs that flag a result only together: a match ratio above weak_match_ratio
  /// and a registered reference crop whose correlation with the image
  /// (SegmentResult::registration_correlation) is below min_registration_correlation. Alone,
  /// each occurs on good results: the correlation falls to 0.89 on a synthetic blob at SNR 4
  /// segmented with Dice 0.99, and across the mice the match ratio reaches 0.65 at Dice 0.86.
  /// A liver model on the CT flipped left to right has both (0.69 and 0.85).
  double weak_match_ratio = 0.5;
  double min_registration_correlation = 0.9;
};

/// What the verdict is made of, and the verdict.
struct QualityControl {
  double volume_ratio = 0;                         ///< segmented volume / the model's finest level's
  double match_cost = 0;                           ///< SegmentResult::final_match_cost
  double chance_cost = 0;                          ///< SegmentResult::chance_match_cost
  double match_ratio = 0;                          ///< match_cost / chance_cost (0 when no level was deformed)
  double shape_residual = 0;                       ///< as QualityControlOptions::max_shape_residual measures it
  bool registration_used = true;                   ///< false: the registration was asked for and rejected
  std::optional<double> registration_correlation;  ///< SegmentResult::registration_correlation, when measured
  int rejected_steps = 0;                          ///< over every level
  int rolled_back_vertices = 0;                    ///< over every level
  int self_intersections = -1;                     ///< of the final surface (-1: not counted)
  bool suspect = false;
  std::string reason;  ///< every limit passed, "; "-joined; empty when not suspect
};

/// The verdict on `result` of `model`, whose segmented volume (as the label map holds it)
/// is `volume_mm3`. A rejected registration alone does not flag a result (its fallback
/// often succeeds); it is named in the reason of a result flagged for another cause.
/// \throw nothing.
QualityControl assess_segmentation(const SegmentResult& result, const SnakeModel& model, double volume_mm3,
                                   const QualityControlOptions& options = {});

void to_json(nlohmann::json& j, const QualityControl& qc);

}  // namespace mrsnake
