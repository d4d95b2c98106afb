#include "evaluation/evaluate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/image_filters_itk.h"

namespace mrsnake {
namespace {

std::string triple(const std::array<std::size_t, 3>& a) {
  std::ostringstream s;
  s << a[0] << "x" << a[1] << "x" << a[2];
  return s.str();
}
std::string triple(const std::array<double, 3>& a) {
  std::ostringstream s;
  s << a[0] << "," << a[1] << "," << a[2];
  return s.str();
}

/// 1 on the voxels of the object that have a 6-neighbour outside it or outside the image.
Volume boundary_of(const Volume& mask) {
  Volume b = mask;
  const auto& n = mask.size;
  for (std::size_t k = 0; k < n[2]; ++k)
    for (std::size_t j = 0; j < n[1]; ++j)
      for (std::size_t i = 0; i < n[0]; ++i) {
        float v = 0;
        if (mask.at(i, j, k) != 0) {
          const bool edge = i == 0 || j == 0 || k == 0 || i + 1 == n[0] || j + 1 == n[1] || k + 1 == n[2];
          v = edge || mask.at(i - 1, j, k) == 0 || mask.at(i + 1, j, k) == 0 || mask.at(i, j - 1, k) == 0 ||
                      mask.at(i, j + 1, k) == 0 || mask.at(i, j, k - 1) == 0 || mask.at(i, j, k + 1) == 0
                  ? 1.0f
                  : 0.0f;
        }
        b.at(i, j, k) = v;
      }
  return b;
}

std::string labels_present(const Volume& v) {
  std::set<long> labels;
  for (float x : v.data) {
    labels.insert(std::lround(x));
    if (labels.size() > 20) break;
  }
  std::ostringstream s;
  bool first = true;
  for (long l : labels) {
    s << (first ? "" : ", ") << l;
    first = false;
  }
  if (labels.size() > 20) s << ", ...";
  return s.str();
}

}  // namespace

void require_same_grid(const Volume& a, const Volume& b, const std::string& a_name, const std::string& b_name) {
  const std::string intro = a_name + " and " + b_name + " are on different grids: ";
  const std::string fix = "; resample " + a_name + " onto the grid of " + b_name;
  if (a.size != b.size) throw InputError(intro + "sizes " + triple(a.size) + " and " + triple(b.size) + fix);
  const double scale = a.max_spacing();
  for (int d = 0; d < 3; ++d)
    if (std::abs(a.spacing[d] - b.spacing[d]) > 1e-5 * scale)
      throw InputError(intro + "spacings " + triple(a.spacing) + " and " + triple(b.spacing) + " mm" + fix);
  for (int d = 0; d < 3; ++d)
    if (std::abs(a.origin[d] - b.origin[d]) > 1e-5 * scale)
      throw InputError(intro + "origins " + triple(a.origin) + " and " + triple(b.origin) + " mm" + fix);
  for (int d = 0; d < 9; ++d)
    if (std::abs(a.direction[d] - b.direction[d]) > 1e-5) throw InputError(intro + "direction matrices differ" + fix);
}

double nearest_rank_percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const auto n = values.size();
  std::size_t rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(n)));
  rank = std::clamp<std::size_t>(rank, 1, n);
  std::nth_element(values.begin(), values.begin() + (rank - 1), values.end());
  return values[rank - 1];
}

SegmentationScores evaluate_segmentation(const Volume& seg, const Volume& truth, int seg_label, int truth_label) {
  require_same_grid(seg, truth, "the segmentation", "the truth");
  if (seg.data.size() != seg.num_voxels() || truth.data.size() != truth.num_voxels())
    throw Error("internal: volume buffer does not match its size");
  Volume s = seg, t = truth;
  SegmentationScores r;
  std::size_t both = 0;
  for (std::size_t i = 0; i < s.data.size(); ++i) {
    const bool in_s = std::lround(seg.data[i]) == seg_label, in_t = std::lround(truth.data[i]) == truth_label;
    s.data[i] = in_s;
    t.data[i] = in_t;
    r.seg_voxels += in_s;
    r.truth_voxels += in_t;
    both += in_s && in_t;
  }
  if (r.truth_voxels == 0)
    throw InputError("the truth has no voxel with label " + std::to_string(truth_label) +
                         " (labels present: " + labels_present(truth) + ")",
                     Remedy::choose_label);
  const double voxel_mm3 = seg.spacing[0] * seg.spacing[1] * seg.spacing[2];
  r.seg_volume_mm3 = r.seg_voxels * voxel_mm3;
  r.truth_volume_mm3 = r.truth_voxels * voxel_mm3;
  r.dice = 2.0 * both / static_cast<double>(r.seg_voxels + r.truth_voxels);
  r.jaccard = both / static_cast<double>(r.seg_voxels + r.truth_voxels - both);
  r.volume_difference_pct = (static_cast<double>(r.seg_voxels) - r.truth_voxels) / r.truth_voxels * 100.0;

  const Volume bt = boundary_of(t);
  for (float v : bt.data) r.truth_boundary_voxels += v != 0;
  if (r.seg_voxels == 0) {
    r.assd_mm = r.hd95_mm = r.hausdorff_mm = std::numeric_limits<double>::infinity();
    return r;
  }
  const Volume bs = boundary_of(s);
  const Volume to_truth = distance_to_voxels(bt), to_seg = distance_to_voxels(bs);
  std::vector<double> d;
  for (std::size_t i = 0; i < bs.data.size(); ++i) {
    if (bs.data[i] != 0) {
      d.push_back(to_truth.data[i]);
      ++r.seg_boundary_voxels;
    }
    if (bt.data[i] != 0) d.push_back(to_seg.data[i]);
  }
  double sum = 0;
  for (double x : d) sum += x;
  r.assd_mm = sum / static_cast<double>(d.size());
  r.hausdorff_mm = *std::max_element(d.begin(), d.end());
  r.hd95_mm = nearest_rank_percentile(std::move(d), 0.95);
  return r;
}

void to_json(nlohmann::json& j, const SegmentationScores& s) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  j = nlohmann::json{{"dice", s.dice},
                     {"jaccard", s.jaccard},
                     {"volume_difference_pct", s.volume_difference_pct},
                     {"assd_mm", num(s.assd_mm)},
                     {"hd95_mm", num(s.hd95_mm)},
                     {"hausdorff_mm", num(s.hausdorff_mm)},
                     {"seg_volume_mm3", s.seg_volume_mm3},
                     {"truth_volume_mm3", s.truth_volume_mm3},
                     {"seg_voxels", s.seg_voxels},
                     {"truth_voxels", s.truth_voxels},
                     {"seg_boundary_voxels", s.seg_boundary_voxels},
                     {"truth_boundary_voxels", s.truth_boundary_voxels}};
}

}  // namespace mrsnake
