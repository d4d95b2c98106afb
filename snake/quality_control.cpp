#include "snake/quality_control.h"

#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "mesh/marching_cubes.h"

namespace mrsnake {
namespace {

// The RMS residual of V after the best similarity onto the model's finest level M (Umeyama),
// over M's equivalent radius: the shape's distance from the model, whatever its pose and size.
double shape_residual(const RowMatrixX3d& V, const RowMatrixX3d& M, double model_volume) {
  if (V.rows() != M.rows() || V.rows() < 4 || !(model_volume > 0)) return 0.0;
  const Eigen::Matrix3Xd src = V.transpose(), dst = M.transpose();
  const Eigen::Matrix4d T = Eigen::umeyama(src, dst, true);
  const Eigen::Matrix3Xd moved = (T.topLeftCorner<3, 3>() * src).colwise() + T.topRightCorner<3, 1>();
  const double rms = std::sqrt((moved - dst).colwise().squaredNorm().mean());
  return rms / std::cbrt(3.0 * model_volume / (4.0 * M_PI));
}

std::string fixed3(const char* format, double a, double b, double c) {
  char text[200];
  std::snprintf(text, sizeof text, format, a, b, c);
  return text;
}

std::string fixed(const char* format, double a, double b) {
  char text[200];
  std::snprintf(text, sizeof text, format, a, b);
  return text;
}

// The limits `qc` passes, each as a short sentence.
std::vector<std::string> limits_passed(const QualityControl& qc, const QualityControlOptions& o, int vertices) {
  std::vector<std::string> reasons;
  if (!(qc.volume_ratio <= o.max_volume_factor && qc.volume_ratio >= 1.0 / o.max_volume_factor))
    reasons.push_back(fixed3("the volume is %.2f times the model's (accepted: %.2f to %.2f)", qc.volume_ratio,
                             1.0 / o.max_volume_factor, o.max_volume_factor));
  if (!(qc.match_ratio <= o.max_match_ratio))
    reasons.push_back(
        fixed("the surface matches the image hardly better than chance (cost %.2f of chance's, "
              "accepted up to %.2f)",
              qc.match_ratio, o.max_match_ratio));
  if (!(qc.shape_residual <= o.max_shape_residual))
    reasons.push_back(fixed("the shape is far from the model's (residual %.2f of its radius, accepted up to %.2f)",
                            qc.shape_residual, o.max_shape_residual));
  if (qc.registration_correlation && *qc.registration_correlation < o.min_registration_correlation &&
      qc.match_ratio > o.weak_match_ratio && qc.match_ratio <= o.max_match_ratio)
    reasons.push_back(
        fixed3("the registered reference correlates poorly with the image (%.2f, accepted from %.2f) "
               "and the surface matches it weakly (cost %.2f of chance's)",
               *qc.registration_correlation, o.min_registration_correlation, qc.match_ratio));
  if (vertices > 0 && qc.rolled_back_vertices > o.max_rolled_back_fraction * vertices)
    reasons.push_back(fixed("%.0f vertices were moved back to undo self-intersections (accepted up to %.0f)",
                            qc.rolled_back_vertices, o.max_rolled_back_fraction * vertices));
  return reasons;
}

}  // namespace

QualityControl assess_segmentation(const SegmentResult& result, const SnakeModel& model, double volume_mm3,
                                   const QualityControlOptions& options) {
  QualityControl qc;
  const int L = model.finest_level();
  const double model_volume = enclosed_volume(TriMesh{model.levels[L], model.faces(L)});
  qc.volume_ratio = model_volume > 0 ? volume_mm3 / model_volume : 0.0;
  if (std::isfinite(result.final_match_cost) && result.chance_match_cost > 0) {
    qc.match_cost = result.final_match_cost;
    qc.chance_cost = result.chance_match_cost;
    qc.match_ratio = qc.match_cost / qc.chance_cost;
  }
  qc.shape_residual = shape_residual(result.surface.V, model.levels[L], model_volume);
  qc.registration_used = !result.registration || result.registration->accepted;
  if (std::isfinite(result.registration_correlation)) qc.registration_correlation = result.registration_correlation;
  for (const LevelOutcome& l : result.levels) {
    qc.rejected_steps += l.snake.rejected_steps;
    qc.rolled_back_vertices += l.rolled_back_vertices;
  }
  qc.self_intersections = result.self_intersections;
  std::vector<std::string> reasons = limits_passed(qc, options, static_cast<int>(model.levels[L].rows()));
  if (!(model_volume > 0)) reasons.insert(reasons.begin(), "the model's finest level encloses no volume; rebuild it");
  if (!result.initialization_failure.empty())
    reasons.insert(reasons.begin(), "the initialization failed (" + result.initialization_failure +
                                        "), so the model was left at its own pose");
  qc.suspect = !reasons.empty();
  if (qc.suspect && !qc.registration_used)
    reasons.push_back("the registration was rejected (" + result.registration->rejection + ")");
  for (const std::string& r : reasons) qc.reason += (qc.reason.empty() ? "" : "; ") + r;
  return qc;
}

void to_json(nlohmann::json& j, const QualityControl& qc) {
  j = {{"volume_ratio_to_model", qc.volume_ratio},
       {"match_cost", qc.match_cost},
       {"chance_cost", qc.chance_cost},
       {"match_ratio", qc.match_ratio},
       {"shape_residual", qc.shape_residual},
       {"registration_used", qc.registration_used},
       {"registration_correlation",
        qc.registration_correlation ? nlohmann::json(*qc.registration_correlation) : nlohmann::json()},
       {"rejected_steps", qc.rejected_steps},
       {"rolled_back_vertices", qc.rolled_back_vertices},
       {"self_intersections", qc.self_intersections},
       {"suspect", qc.suspect},
       {"reason", qc.reason}};
}

}  // namespace mrsnake
