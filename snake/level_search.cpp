#include "snake/level_search.h"

#include <algorithm>

#include "snake/appearance.h"
#include "snake/forces.h"

namespace mrsnake {

LevelSearches::LevelSearches(const SnakeModel& model, const NormalizedPyramid& pyramid, bool profiles,
                             const LevelSearchOptions& options)
    : model_(model), pyramid_(pyramid), profiles_(profiles), options_(options) {
  const int L = model.finest_level();
  pyr_.resize(L + 1);
  edges_.resize(L + 1);
  for (int j = 0; j <= L; ++j) {
    edges_[j] = mean_edge_length(model.levels[j], model.faces(j));
    pyr_[j] = pyramid_level_for_edge(edges_[j], pyramid.spacings, options.edge_per_voxel);
  }
}

double LevelSearches::range_mm(int j, double edge_fraction, double min_voxels) const {
  const std::vector<double>& spacings = pyramid_.spacings;
  double r = std::max(min_voxels * spacings[pyr_[j]], edge_fraction * edges_[j]);
  if (options_.max_range_voxels > 0) r = std::min(r, options_.max_range_voxels * spacings[pyr_[j]]);
  return r;
}

std::pair<ExternalSearch, double> LevelSearches::search(int j, double range_mm, RegionStats stats,
                                                        const VertexRings* rings, double profile_step_fraction) const {
  const int p = pyr_[j];
  const VolumeSampler* sampler = &pyramid_.samplers[p];
  NormalSearchOptions so;
  so.range_mm = range_mm;
  so.min_gain = options_.min_gain;
  so.rings = rings;
  so.ring_weight = options_.ring_weight;
  so.ring_full_weight_cost = options_.ring_full_weight_cost;
  if (profiles_) {
    const LevelAppearance* la = &model_.appearance->levels[j];
    so.step_mm = profile_step_fraction * la->spacing_mm;
    so.max_cost = options_.max_profile_cost;
    so.distance_penalty = options_.profile_distance_penalty;
    return {[sampler, la, so](const RowMatrixX3d& V, const RowMatrixX3d& N) {
              return search_profiles(*sampler, V, N, la->profiles, la->spacing_mm, so);
            },
            so.step_mm};
  }
  so.step_mm = options_.step_voxels * pyramid_.spacings[p];
  so.window_mm = options_.window_voxels * pyramid_.spacings[p];
  so.max_cost = options_.max_edge_cost;
  so.distance_penalty = options_.edge_distance_penalty;
  return {[sampler, stats, so](const RowMatrixX3d& V, const RowMatrixX3d& N) {
            return search_step_edges(*sampler, V, N, stats, so);
          },
          so.step_mm};
}

}  // namespace mrsnake
