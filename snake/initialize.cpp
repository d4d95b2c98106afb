#include "snake/initialize.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

#include "mesh/errors.h"
#include "snake/appearance.h"
#include "snake/rasterize.h"
#include "snake/sampler.h"

namespace mrsnake {

RowMatrixX3d Similarity::apply(const RowMatrixX3d& V) const {
  RowMatrixX3d out(V.rows(), 3);
  const Eigen::Matrix3d A = scale * rotation;
  for (int v = 0; v < V.rows(); ++v) out.row(v) = (A * V.row(v).transpose() + translation).transpose();
  return out;
}

Similarity Similarity::compose(const Similarity& o) const {
  Similarity s;
  s.rotation = rotation * o.rotation;
  s.scale = scale * o.scale;
  s.translation = scale * (rotation * o.translation) + translation;
  return s;
}

double Similarity::rotation_angle_deg() const { return Eigen::AngleAxisd(rotation).angle() * 180.0 / M_PI; }

Moments mask_moments(const Volume& mask) {
  Moments m;
  double count = 0;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sum2 = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < mask.size[2]; ++k)
    for (std::size_t j = 0; j < mask.size[1]; ++j)
      for (std::size_t i = 0; i < mask.size[0]; ++i) {
        if (!(mask.at(i, j, k) > 0.5f)) continue;
        const auto p = mask.index_to_physical(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
        const Eigen::Vector3d x(p[0], p[1], p[2]);
        count += 1;
        sum += x;
        sum2 += x * x.transpose();
      }
  if (count == 0) return m;
  m.volume = count * mask.spacing[0] * mask.spacing[1] * mask.spacing[2];
  m.centroid = sum / count;
  m.covariance = sum2 / count - m.centroid * m.centroid.transpose();
  return m;
}

double otsu_threshold(const Volume& image, const std::array<long, 3>& lo, const std::array<long, 3>& hi) {
  float mn = std::numeric_limits<float>::max(), mx = std::numeric_limits<float>::lowest();
  for (long k = lo[2]; k <= hi[2]; ++k)
    for (long j = lo[1]; j <= hi[1]; ++j)
      for (long i = lo[0]; i <= hi[0]; ++i) {
        const float v = image.at(i, j, k);
        mn = std::min(mn, v);
        mx = std::max(mx, v);
      }
  if (!(mx > mn)) return mn;
  constexpr int bins = 256;
  std::vector<double> hist(bins, 0.0);
  const double scale = (bins - 1) / static_cast<double>(mx - mn);
  for (long k = lo[2]; k <= hi[2]; ++k)
    for (long j = lo[1]; j <= hi[1]; ++j)
      for (long i = lo[0]; i <= hi[0]; ++i) hist[static_cast<int>((image.at(i, j, k) - mn) * scale)] += 1;
  const double total = std::accumulate(hist.begin(), hist.end(), 0.0);
  double sum_all = 0;
  for (int b = 0; b < bins; ++b) sum_all += b * hist[b];
  double w0 = 0, sum0 = 0, best = -1;
  int best_b = 0;
  for (int b = 0; b < bins - 1; ++b) {
    w0 += hist[b];
    sum0 += b * hist[b];
    const double w1 = total - w0;
    if (w0 == 0 || w1 == 0) continue;
    const double m0 = sum0 / w0, m1 = (sum_all - sum0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) {
      best = between;
      best_b = b;
    }
  }
  return mn + (best_b + 1) / scale;
}

void mesh_index_box(const Volume& image, const RowMatrixX3d& V, double margin, std::array<long, 3>& lo,
                    std::array<long, 3>& hi) {
  Eigen::Vector3d mn = Eigen::Vector3d::Constant(std::numeric_limits<double>::max()), mx = -mn;
  for (int v = 0; v < V.rows(); ++v) {
    const auto idx = image.physical_to_index({V(v, 0), V(v, 1), V(v, 2)});
    const Eigen::Vector3d x(idx[0], idx[1], idx[2]);
    mn = mn.cwiseMin(x);
    mx = mx.cwiseMax(x);
  }
  const Eigen::Vector3d m = margin * (mx - mn);
  for (int a = 0; a < 3; ++a) {
    const long last = static_cast<long>(image.size[a]) - 1;
    lo[a] = std::clamp(static_cast<long>(std::floor(mn[a] - m[a])), 0L, last);
    hi[a] = std::clamp(static_cast<long>(std::ceil(mx[a] + m[a])), 0L, last);
  }
}

ThresholdClasses threshold_classes(const Volume& image, const Volume& smooth, const std::array<long, 3>& lo,
                                   const std::array<long, 3>& hi, std::size_t max_samples) {
  ThresholdClasses c;
  // The box in the smooth image's indices.
  std::array<long, 3> slo{}, shi{};
  for (int a = 0; a < 3; ++a) {
    slo[a] = std::numeric_limits<long>::max();
    shi[a] = std::numeric_limits<long>::min();
  }
  for (long corner = 0; corner < 8; ++corner) {
    const auto p = image.index_to_physical(static_cast<double>((corner & 1) ? hi[0] : lo[0]),
                                           static_cast<double>((corner & 2) ? hi[1] : lo[1]),
                                           static_cast<double>((corner & 4) ? hi[2] : lo[2]));
    const auto q = smooth.physical_to_index(p);
    for (int a = 0; a < 3; ++a) {
      const long last = static_cast<long>(smooth.size[a]) - 1;
      slo[a] = std::min(slo[a], std::clamp(static_cast<long>(std::floor(q[a])), 0L, last));
      shi[a] = std::max(shi[a], std::clamp(static_cast<long>(std::ceil(q[a])), 0L, last));
    }
  }
  c.threshold = otsu_threshold(smooth, slo, shi);
  const VolumeSampler coarse(smooth);
  std::vector<float> upper, lower;
  double box_voxels = 1;
  for (int a = 0; a < 3; ++a) box_voxels *= static_cast<double>(std::max(0L, hi[a] - lo[a] + 1));
  const long stride = std::max(
      1L,
      static_cast<long>(std::ceil(std::cbrt(box_voxels / static_cast<double>(std::max<std::size_t>(1, max_samples))))));
  for (long k = lo[2]; k <= hi[2]; k += stride)
    for (long j = lo[1]; j <= hi[1]; j += stride)
      for (long i = lo[0]; i <= hi[0]; i += stride) {
        const auto p = image.index_to_physical(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
        const float v = image.at(i, j, k);
        (coarse.value(Eigen::Vector3d(p[0], p[1], p[2])) > c.threshold ? upper : lower).push_back(v);
      }
  const auto median = [](std::vector<float>& a) {
    if (a.empty()) return 0.0;
    std::nth_element(a.begin(), a.begin() + static_cast<long>(a.size() / 2), a.end());
    return static_cast<double>(a[a.size() / 2]);
  };
  c.upper_median = median(upper);
  c.lower_median = median(lower);
  return c;
}

namespace {
// Eigenvectors sorted by decreasing eigenvalue, as a right-handed rotation's columns.
void principal_axes(const Eigen::Matrix3d& cov, Eigen::Matrix3d& axes, Eigen::Vector3d& values) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  values = es.eigenvalues().reverse();
  axes = es.eigenvectors().rowwise().reverse();
  if (axes.determinant() < 0) axes.col(2) *= -1;
}
}  // namespace

Similarity moments_alignment(const Volume& image, const TriMesh& model, const MomentsOptions& options) {
  // Region of interest: the model's box in index space, grown.
  std::array<long, 3> lo{}, hi{};
  mesh_index_box(image, model.V, options.roi_margin, lo, hi);
  const double threshold = std::isnan(options.threshold) ? otsu_threshold(image, lo, hi) : options.threshold;
  Volume mask;
  mask.size = image.size;
  mask.spacing = image.spacing;
  mask.origin = image.origin;
  mask.direction = image.direction;
  mask.data.assign(mask.num_voxels(), 0.0f);
  for (long k = lo[2]; k <= hi[2]; ++k)
    for (long j = lo[1]; j <= hi[1]; ++j)
      for (long i = lo[0]; i <= hi[0]; ++i) {
        const float v = image.at(i, j, k);
        if (options.bright_object ? v > threshold : v < threshold) mask.at(i, j, k) = 1.0f;
      }
  const Moments target = mask_moments(mask);
  if (target.volume <= 0)
    throw AlgorithmError("no voxel near the model passes the threshold; check the image and the model's pose");
  const Moments source = mask_moments(rasterize_mesh(model, image));
  if (source.volume <= 0)
    throw AlgorithmError("the model does not cover any voxel of the image; check that model and image overlap");

  Similarity s;
  s.scale = std::cbrt(target.volume / source.volume);
  if (options.rotate) {
    Eigen::Matrix3d As, At;
    Eigen::Vector3d ls, lt;
    principal_axes(source.covariance, As, ls);
    principal_axes(target.covariance, At, lt);
    const auto separated = [&](const Eigen::Vector3d& l) {
      return (l[0] - l[1]) > options.min_axis_separation * l[0] && (l[1] - l[2]) > options.min_axis_separation * l[0];
    };
    if (separated(ls) && separated(lt)) {
      // Among the four proper sign choices, the rotation closest to the identity.
      double best_angle = std::numeric_limits<double>::max();
      Eigen::Matrix3d best = Eigen::Matrix3d::Identity();
      for (int sx : {-1, 1})
        for (int sy : {-1, 1}) {
          Eigen::Matrix3d A = At;
          A.col(0) *= sx;
          A.col(1) *= sy;
          A.col(2) *= sx * sy;
          const Eigen::Matrix3d R = A * As.transpose();
          const double angle = Eigen::AngleAxisd(R).angle();
          if (angle < best_angle) {
            best_angle = angle;
            best = R;
          }
        }
      if (best_angle * 180.0 / M_PI <= options.max_rotation_deg) s.rotation = best;
    }
  }
  s.translation = target.centroid - s.scale * (s.rotation * source.centroid);
  return s;
}

Similarity fit_similarity_to_targets(RowMatrixX3d& V, const RowMatrixX3i& F, const ExternalSearch& search,
                                     const TargetFitOptions& options, int* iterations_done) {
  Similarity total;
  RowMatrixX3d N;
  const int n = static_cast<int>(V.rows());
  // The pose whose search matched best so far: a fit on weak or ambiguous evidence (another
  // animal's profiles, a thin structure) drifts on while its matches get worse.
  Similarity best_total;
  RowMatrixX3d best_V = V;
  double best_cost = std::numeric_limits<double>::infinity();
  int since_best = 0;
  bool stopped_worse = false;
  int it = 0;
  for (; it < options.iterations; ++it) {
    vertex_normals(V, F, N);
    const SearchResult found = search(V, N);
    const double cost = found.costs.mean();
    if (cost < best_cost) {
      best_cost = cost;
      best_total = total;
      best_V = V;
      since_best = 0;
    } else if (options.patience > 0 && ++since_best >= options.patience) {
      stopped_worse = true;  // V was searched and matched worse than best_V
      break;
    }
    // Keep the best-matching (1 − trim) of the vertices.
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    const int keep = std::max(4, static_cast<int>(std::lround(n * (1.0 - options.trim_fraction))));
    if (keep < n)
      std::nth_element(order.begin(), order.begin() + keep, order.end(),
                       [&](int a, int b) { return found.costs[a] < found.costs[b]; });
    const int m = std::min(keep, n);
    Eigen::Matrix3Xd src(3, m), dst(3, m);
    for (int k = 0; k < m; ++k) {
      const int v = order[k];
      src.col(k) = V.row(v).transpose();
      dst.col(k) = (V.row(v) + found.offsets[v] * N.row(v)).transpose();
    }
    const Eigen::Matrix4d T = Eigen::umeyama(src, dst, options.with_scale);
    Similarity step;
    const Eigen::Matrix3d A = T.topLeftCorner<3, 3>();
    step.scale = options.with_scale ? std::cbrt(A.determinant()) : 1.0;
    step.rotation = A / step.scale;
    step.translation = T.topRightCorner<3, 1>();
    const RowMatrixX3d moved = step.apply(V);
    const double motion = (moved - V).rowwise().norm().mean();
    V = moved;
    total = step.compose(total);
    if (motion < options.tolerance_mm) {
      ++it;
      break;
    }
  }
  if (options.patience > 0 && std::isfinite(best_cost)) {
    // Otherwise the last pose has not been searched yet: judge it too.
    if (!stopped_worse) {
      vertex_normals(V, F, N);
      stopped_worse = !(search(V, N).costs.mean() < best_cost);
    }
    if (stopped_worse) {
      V = best_V;
      total = best_total;
    }
  }
  if (iterations_done) *iterations_done = it;
  return total;
}

ReferenceRegistration register_reference(const Volume& reference, const std::vector<const Volume*>& pyramid,
                                         double level0_scale, double level0_offset,
                                         const ReferenceRegistrationOptions& options,
                                         const Eigen::Vector3d& start_translation) {
  const auto t0 = std::chrono::steady_clock::now();
  ReferenceRegistration out;
  std::vector<double> spacings;
  for (const Volume* v : pyramid) spacings.push_back(v->max_spacing());
  const double ref_spacing = reference.max_spacing();
  out.pyramid_level = pyramid_level_for_edge(ref_spacing, spacings, 1.0);
  RegistrationOptions ro = options.itk;
  for (int a = 0; a < 3; ++a) ro.initial_translation[a] = start_translation[a];
  if (out.pyramid_level == 0) {
    ro.moving_intensity_scale = level0_scale;
    ro.moving_intensity_offset = level0_offset;
  }
  try {
    out.result = register_similarity(reference, *pyramid[out.pyramid_level], ro);
    out.ran = true;
  } catch (const Error& e) {  // no overlap, or ITK gave up: the caller falls back
    out.rejection = e.what();
  }
  if (out.ran) {
    const RegistrationTransform& t = out.result.transform;
    bool finite = std::isfinite(out.result.final_metric) && std::isfinite(t.scale);
    for (double m : t.matrix) finite = finite && std::isfinite(m);
    for (double m : t.offset) finite = finite && std::isfinite(m);
    if (!finite) {
      out.rejection = "the registration diverged (non-finite result)";
    } else if (!(out.result.final_metric < out.result.initial_metric)) {
      out.rejection = "the registration did not improve the metric (" + std::to_string(out.result.initial_metric) +
                      " at the start, " + std::to_string(out.result.final_metric) + " at the end)";
    } else if (t.scale < options.min_scale || t.scale > options.max_scale) {
      out.rejection = "the registration's scale " + std::to_string(t.scale) + " is outside [" +
                      std::to_string(options.min_scale) + ", " + std::to_string(options.max_scale) + "]";
    } else {
      out.accepted = true;
      Eigen::Matrix3d A;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) A(r, c) = t.matrix[3 * r + c];
      out.pose.scale = t.scale;
      out.pose.rotation = A / t.scale;
      out.pose.translation = Eigen::Vector3d(t.offset[0], t.offset[1], t.offset[2]);
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace mrsnake
