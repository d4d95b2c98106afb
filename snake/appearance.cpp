#include "snake/appearance.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "snake/sampler.h"
#include "snake/surface_geometry.h"

namespace mrsnake {

int pyramid_level_for_edge(double edge_mm, const std::vector<double>& spacings, double edge_per_voxel) {
  const double target = edge_mm / edge_per_voxel;
  int best = 0;
  double best_d = std::numeric_limits<double>::max();
  for (int k = 0; k < static_cast<int>(spacings.size()); ++k) {
    const double d = std::abs(std::log(spacings[k] / target));
    if (d < best_d - 1e-9) {
      best_d = d;
      best = k;
    }
  }
  return best;
}

double mean_edge_length(const RowMatrixX3d& V, const RowMatrixX3i& F) {
  double sum = 0;
  for (int f = 0; f < F.rows(); ++f)
    for (int c = 0; c < 3; ++c) sum += (V.row(F(f, c)) - V.row(F(f, (c + 1) % 3))).norm();
  return F.rows() ? sum / (3.0 * F.rows()) : 0.0;
}

namespace {
void median_and_spread(std::vector<float>& a, double& median, double& spread) {
  if (a.empty()) {
    median = spread = 0;
    return;
  }
  const std::size_t mid = a.size() / 2;
  std::nth_element(a.begin(), a.begin() + static_cast<long>(mid), a.end());
  median = a[mid];
  for (float& x : a) x = static_cast<float>(std::abs(x - median));
  std::nth_element(a.begin(), a.begin() + static_cast<long>(mid), a.end());
  spread = 1.4826 * a[mid];
}
}  // namespace

namespace {
// The sum of the profiles of v's closed 1-ring (v and its neighbours), into sum[0..K−1]: their
// mean times valence + 1. In the mean, the reference image's noise averages out, and a
// neighbouring tissue, coherent along the surface, does not.
void closed_ring_profile_sum(const Eigen::MatrixXf& P, const VertexRings& rings, int v, std::vector<double>& sum) {
  const int K = static_cast<int>(P.cols());
  for (int k = 0; k < K; ++k) sum[k] = P(v, k);
  for (int i = rings.offsets[v]; i < rings.offsets[v + 1]; ++i)
    for (int k = 0; k < K; ++k) sum[k] += P(rings.neighbors[i], k);
}

// Per vertex, the offset along its normal of the image's edge: on the mean profile of its
// closed 1-ring (P sampled at `spacing`), the crossing of the mid level between the samples
// two steps in and out that lies nearest the centre; then one ring average, and the clamp to
// ±limits[v]. A vertex without such a crossing (no step there) keeps offset 0.
// \pre P.cols() >= 5 (two samples on each side of the centre).
Eigen::VectorXd edge_offsets(const Eigen::MatrixXf& P, const VertexRings& rings, double spacing,
                             const Eigen::VectorXd& limits) {
  const int n = static_cast<int>(P.rows()), K = static_cast<int>(P.cols()), half = K / 2;
  Eigen::VectorXd offsets = Eigen::VectorXd::Zero(n);
  std::vector<double> mean(static_cast<std::size_t>(K));
  for (int v = 0; v < n; ++v) {
    closed_ring_profile_sum(P, rings, v, mean);  // a scaled mean: the crossing does not change
    const double mid = 0.5 * (mean[half - 2] + mean[half + 2]);
    if (!(std::abs(mean[half - 2] - mean[half + 2]) > 1e-9)) continue;
    double nearest = std::numeric_limits<double>::infinity();  // in samples from the centre
    for (int k = half - 2; k < half + 2; ++k) {
      const double y0 = mean[k] - mid, y1 = mean[k + 1] - mid;
      if ((y0 <= 0 && y1 > 0) || (y0 >= 0 && y1 < 0)) {
        const double t = (k - half) + y0 / (y0 - y1);
        if (std::abs(t) < std::abs(nearest)) nearest = t;
      }
    }
    if (std::isfinite(nearest)) offsets[v] = nearest * spacing;
  }
  smooth_on_rings(rings, offsets, 1);
  return offsets.cwiseMax(-limits).cwiseMin(limits);
}

// How far a binary label's boundary can lie from the object's along each unit normal, per
// voxel rounding: half the largest of the voxel's axis steps projected on the normal (half a
// voxel across an axis-aligned plane, less across an oblique one), times `voxels` halves.
Eigen::VectorXd rounding_limits(const Volume& image, const RowMatrixX3d& N, double voxels) {
  Eigen::VectorXd limits(N.rows());
  for (int v = 0; v < N.rows(); ++v) {
    double largest = 0;
    for (int c = 0; c < 3; ++c) {  // axis c's unit vector is column c of the direction matrix
      const double along =
          image.direction[c] * N(v, 0) + image.direction[3 + c] * N(v, 1) + image.direction[6 + c] * N(v, 2);
      largest = std::max(largest, std::abs(along) * image.spacing[c]);
    }
    limits[v] = voxels * largest;
  }
  return limits;
}
}  // namespace

Appearance build_appearance(const std::vector<Volume>& pyramid, const std::vector<RowMatrixX3d>& levels,
                            const std::vector<RowMatrixX3i>& faces, const AppearanceOptions& options,
                            ProfileAlignmentReport* alignment) {
  Appearance a;
  a.half_length = options.half_length;
  std::vector<double> spacings;
  for (const Volume& v : pyramid) spacings.push_back(v.max_spacing());
  RowMatrixX3d N;
  std::vector<int> pyramid_levels;
  for (std::size_t j = 0; j < levels.size(); ++j) {
    const int p = pyramid_level_for_edge(mean_edge_length(levels[j], faces[j]), spacings);
    pyramid_levels.push_back(p);
    const VolumeSampler sampler(pyramid[p]);
    vertex_normals(levels[j], faces[j], N);
    LevelAppearance la;
    la.spacing_mm = spacings[p];
    la.profiles = sample_profiles(sampler, levels[j], N, options.half_length, la.spacing_mm);
    a.levels.push_back(std::move(la));
  }
  // Region statistics on the finest level, at full resolution.
  const VolumeSampler sampler(pyramid[0]);
  const RowMatrixX3d& V = levels.back();
  vertex_normals(V, faces.back(), N);
  const double h = 0.5 * pyramid[0].max_spacing();
  a.shell_mm = options.shell_voxels * pyramid[0].max_spacing();
  const int steps = std::max(1, static_cast<int>(std::floor(a.shell_mm / h)));
  std::vector<float> in, out;
  for (int v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d x = V.row(v), n = N.row(v);
    for (int s = 1; s <= steps; ++s) {
      in.push_back(sampler.value(x - (s * h) * n));
      out.push_back(sampler.value(x + (s * h) * n));
    }
  }
  median_and_spread(in, a.region.inside, a.inside_spread);
  median_and_spread(out, a.region.outside, a.outside_spread);

  ProfileAlignmentReport report;
  report.step_residual = profile_step_residual(a, faces);
  const bool wanted =
      options.alignment == ProfileAlignment::edges ||
      (options.alignment == ProfileAlignment::automatic && report.step_residual <= options.clean_edge_max_residual);
  report.to_edges = wanted && options.half_length >= 2;  // the crossing needs two samples a side
  if (report.to_edges) {
    // Only the levels sampled at full resolution: the label's rounding is below a coarser
    // level's sampling, and a coarse level lies off the surface by more than that anyway.
    const VolumeSampler sampler(pyramid[0]);
    long count = 0;
    for (std::size_t j = 0; j < levels.size(); ++j) {
      if (pyramid_levels[j] != 0) continue;
      const int n = static_cast<int>(levels[j].rows());
      LevelAppearance& la = a.levels[j];
      vertex_normals(levels[j], faces[j], N);
      const Eigen::VectorXd shift = edge_offsets(la.profiles, build_vertex_rings(faces[j], n), la.spacing_mm,
                                                 rounding_limits(pyramid[0], N, options.max_alignment_voxels));
      const RowMatrixX3d centres = levels[j] + shift.asDiagonal() * N;
      la.profiles = sample_profiles(sampler, centres, N, options.half_length, la.spacing_mm);
      la.centre = ProfileCentre::edges;
      ++report.levels_aligned;
      report.mean_shift_mm += shift.sum();
      report.mean_abs_shift_mm += shift.cwiseAbs().sum();
      count += n;
    }
    if (count > 0) {
      report.mean_shift_mm /= static_cast<double>(count);
      report.mean_abs_shift_mm /= static_cast<double>(count);
    }
  }
  if (alignment) *alignment = report;
  return a;
}

std::string to_string(ProfileCentre centre) {
  switch (centre) {
    case ProfileCentre::labels: return "labels";
    case ProfileCentre::edges: return "edges";
    case ProfileCentre::unrecorded: break;
  }
  return "unrecorded";
}

ProfileAlignment parse_profile_alignment(const std::string& name) {
  if (name == "auto") return ProfileAlignment::automatic;
  if (name == "edges") return ProfileAlignment::edges;
  if (name == "labels") return ProfileAlignment::labels;
  throw InputError("unknown profile alignment '" + name + "'; use auto, edges or labels");
}

void to_json(nlohmann::json& j, const ProfileAlignmentReport& r) {
  j = nlohmann::json{
      {"centred_on", r.to_edges ? "edges" : "labels"},
      {"step_residual", std::isfinite(r.step_residual) ? nlohmann::json(r.step_residual) : nlohmann::json()},
      {"levels_aligned", r.levels_aligned},
      {"mean_shift_mm", r.mean_shift_mm},
      {"mean_abs_shift_mm", r.mean_abs_shift_mm}};
}

double profile_step_residual(const Appearance& a, const std::vector<RowMatrixX3i>& faces) {
  const double inside = a.region.inside, outside = a.region.outside;
  const double contrast = std::abs(inside - outside);
  if (!(contrast > 1e-9) || faces.size() != a.levels.size()) return std::numeric_limits<double>::infinity();
  double worst = -1;
  std::vector<double> residuals, mean;
  for (std::size_t j = 0; j < a.levels.size(); ++j) {
    const auto& P = a.levels[j].profiles;
    const int n = static_cast<int>(P.rows()), K = static_cast<int>(P.cols()), half = K / 2;
    const bool faces_fit = faces[j].size() == 0 || (faces[j].minCoeff() >= 0 && faces[j].maxCoeff() < n);
    if (n == 0 || K == 0 || !faces_fit) return std::numeric_limits<double>::infinity();
    const VertexRings rings = build_vertex_rings(faces[j], n);
    residuals.clear();
    mean.assign(static_cast<std::size_t>(K), 0.0);
    for (int v = 0; v < n; ++v) {
      closed_ring_profile_sum(P, rings, v, mean);  // divided by valence + 1 below
      double sum2 = 0;
      for (int k = 0; k < K; ++k) {
        const double ideal = k < half ? inside : (k > half ? outside : 0.5 * (inside + outside));
        const double d = mean[k] / (rings.valence(v) + 1) - ideal;
        sum2 += d * d;
      }
      residuals.push_back(std::sqrt(sum2 / K) / contrast);
    }
    const auto p90 = residuals.begin() + static_cast<long>(residuals.size() * 9 / 10);
    std::nth_element(residuals.begin(), p90, residuals.end());
    worst = std::max(worst, *p90);
  }
  return worst < 0 ? std::numeric_limits<double>::infinity() : worst;
}

void to_json(nlohmann::json& j, const Appearance& a) {
  j = nlohmann::json{{"levels", a.levels.size()},
                     {"samples_per_profile", 2 * a.half_length + 1},
                     {"inside_median", a.region.inside},
                     {"outside_median", a.region.outside},
                     {"inside_spread", a.inside_spread},
                     {"outside_spread", a.outside_spread},
                     {"shell_mm", a.shell_mm}};
  nlohmann::json spacing = nlohmann::json::array(), centred_on = nlohmann::json::array();
  for (const auto& l : a.levels) {
    spacing.push_back(l.spacing_mm);
    centred_on.push_back(to_string(l.centre));
  }
  j["profile_spacing_mm"] = spacing;
  j["profiles_centred_on"] = centred_on;
}

}  // namespace mrsnake
