#pragma once
/// \file evaluate.h
/// Scores a label volume against a truth on the same grid: overlap (Dice, Jaccard), volume
/// difference, and surface distances between boundary voxels in physical space.
///
/// Surface distances. The boundary of an object is its voxels that have a 6-neighbour
/// outside it (or outside the image). For each boundary voxel of one object, its distance
/// is the Euclidean distance in mm from its centre to the nearest boundary-voxel centre of
/// the other object (from ITK's SignedMaurerDistanceMapImageFilter with image spacing; not
/// ITK's HausdorffDistanceImageFilter, whose "average" is not this). Both directions are
/// pooled: ASSD is their mean, HD95 their 95th percentile (nearest rank: the
/// ⌈0.95·N⌉-th smallest of the N pooled distances), the Hausdorff distance their maximum.
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "mesh/volume.h"

namespace mrsnake {

struct SegmentationScores {
  double dice = 0;                   ///< 2|S∩T| / (|S| + |T|)
  double jaccard = 0;                ///< |S∩T| / |S∪T|
  double volume_difference_pct = 0;  ///< (V_seg − V_truth) / V_truth · 100
  double assd_mm = 0;                ///< average symmetric surface distance (infinite if seg is empty)
  double hd95_mm = 0;                ///< 95th percentile of the pooled surface distances
  double hausdorff_mm = 0;           ///< largest surface distance
  double seg_volume_mm3 = 0, truth_volume_mm3 = 0;
  std::size_t seg_voxels = 0, truth_voxels = 0;
  std::size_t seg_boundary_voxels = 0, truth_boundary_voxels = 0;
};

/// Throws unless both volumes share size, spacing, origin and direction (to a relative
/// 1e-5 of the spacing), naming what differs.
/// \throw InputError "SEG and TRUTH are on different grids: sizes 64×64×64 and ...".
void require_same_grid(const Volume& a, const Volume& b, const std::string& a_name, const std::string& b_name);

/// Scores the voxels equal to `seg_label` in seg against those equal to `truth_label` in
/// truth (values are rounded to the nearest integer). An empty segmentation scores Dice 0
/// and infinite distances.
/// \pre the volumes' buffers match their sizes.
/// \throw InputError if the grids differ or the truth has no voxel with its label.
SegmentationScores evaluate_segmentation(const Volume& seg, const Volume& truth, int seg_label = 1,
                                         int truth_label = 1);

/// The q-quantile (0 < q <= 1) by nearest rank: the ⌈q·N⌉-th smallest value; 0 if empty.
double nearest_rank_percentile(std::vector<double> values, double q);

/// Keys: dice, jaccard, volume_difference_pct, assd_mm, hd95_mm, hausdorff_mm,
/// seg_volume_mm3, truth_volume_mm3, seg_voxels, truth_voxels, seg_boundary_voxels,
/// truth_boundary_voxels. Infinite distances are written as null.
void to_json(nlohmann::json& j, const SegmentationScores& s);

}  // namespace mrsnake
