#pragma once
/// \file level_search.h
/// The external search of each mesh level of the segmentation (segment.h): the pyramid level
/// it runs on, its search range, and the profile or step-edge search there (forces.h).
#include <utility>
#include <vector>

#include "snake/deformable_surface.h"
#include "snake/image_pyramid.h"
#include "snake/segment.h"

namespace mrsnake {

/// The search's settings; segment() takes each from the SegmentOptions field of the same
/// meaning (segment.h, where their defaults are).
struct LevelSearchOptions {
  double edge_per_voxel = 0;            ///< SegmentOptions::edge_per_voxel
  double step_voxels = 0;               ///< ::step_voxels (step-edge force)
  double window_voxels = 0;             ///< ::window_voxels (step-edge force)
  double max_edge_cost = 0;             ///< ::max_edge_cost
  double max_profile_cost = 0;          ///< ::max_profile_cost
  double profile_distance_penalty = 0;  ///< ::profile_distance_penalty
  double edge_distance_penalty = 0;     ///< ::edge_distance_penalty
  double min_gain = 0;                  ///< ::search_min_gain
  double ring_weight = 0;               ///< ::cost_ring_weight
  double ring_full_weight_cost = 0;     ///< ::cost_ring_full_weight_cost
  double max_range_voxels = 0;          ///< ::max_range_voxels (0: no cap)
};

/// Every mesh level's place on the pyramid and the search built there. Holds references to
/// the model and the pyramid, which must outlive it (and the searches it returns).
class LevelSearches {
 public:
  /// profiles: the profile force (the model's appearance, which then must match its levels);
  /// otherwise the step-edge force.
  LevelSearches(const SnakeModel& model, const NormalizedPyramid& pyramid, bool profiles,
                const LevelSearchOptions& options);

  bool profiles() const { return profiles_; }
  double edge_mm(int j) const { return edges_[j]; }                    ///< mean edge of the model's level j
  int pyramid_level(int j) const { return pyr_[j]; }                   ///< the pyramid level mesh level j runs on
  double voxel_mm(int j) const { return pyramid_.spacings[pyr_[j]]; }  ///< that level's voxel (max spacing)

  /// The search range at level j: max(min_voxels·voxel, edge_fraction·edge_j), at most
  /// max_range_voxels voxels when that is set.
  double range_mm(int j, double edge_fraction, double min_voxels) const;

  /// The search of level j and its step (mm): the profiles (a step of profile_step_fraction of
  /// the profile spacing) or the step edges between `stats`; `rings` (may be null) shares
  /// the evidence with the 1-ring.
  std::pair<ExternalSearch, double> search(int j, double range_mm, RegionStats stats, const VertexRings* rings,
                                           double profile_step_fraction) const;

 private:
  const SnakeModel& model_;
  const NormalizedPyramid& pyramid_;
  bool profiles_;
  LevelSearchOptions options_;
  std::vector<int> pyr_;
  std::vector<double> edges_;
};

}  // namespace mrsnake
