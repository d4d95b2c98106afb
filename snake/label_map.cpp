#include "snake/label_map.h"

#include <memory>
#include <stdexcept>
#include <unordered_map>

#include "mesh/distance.h"
#include "snake/rasterize.h"

namespace mrsnake {
namespace {

// The voxels that more than one surface encloses, with every structure that claims each.
using Claims = std::unordered_map<std::size_t, std::vector<int>>;

Eigen::Vector3d voxel_centre(const Volume& grid, std::size_t index) {
  const std::size_t i = index % grid.size[0], j = (index / grid.size[0]) % grid.size[1],
                    k = index / (grid.size[0] * grid.size[1]);
  const auto p = grid.index_to_physical(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k));
  return {p[0], p[1], p[2]};
}

// Each contested voxel to the claimant it lies deepest inside.
void settle_claims(const Claims& claims, const std::vector<TriMesh>& surfaces, StructureLabelMap& map,
                   std::vector<int>& owner) {
  std::vector<std::unique_ptr<SurfaceLocator>> locators(surfaces.size());
  const auto locator = [&](int s) -> const SurfaceLocator& {
    if (!locators[s]) locators[s] = std::make_unique<SurfaceLocator>(surfaces[s]);
    return *locators[s];
  };
  for (const auto& [index, claimants] : claims) {
    const Eigen::Vector3d p = voxel_centre(map.labels, index);
    int best = claimants.front();
    double deepest = -1;
    for (const int s : claimants) {
      ++map.contested[s];
      const double depth = locator(s).closest(p).distance;
      if (depth > deepest) {
        deepest = depth;
        best = s;
      }
    }
    owner[index] = best;
  }
}

}  // namespace

StructureLabelMap structure_label_map(const std::vector<TriMesh>& surfaces, const std::vector<int>& values,
                                      const Volume& grid) {
  if (surfaces.size() != values.size())
    throw std::invalid_argument("structure_label_map: one value per surface is needed");
  StructureLabelMap map;
  map.voxels.assign(surfaces.size(), 0);
  map.contested.assign(surfaces.size(), 0);
  std::vector<int> owner(grid.num_voxels(), -1);
  Claims claims;
  // One raster at a time: the memory is that of two volumes, whatever the number of structures.
  for (std::size_t s = 0; s < surfaces.size(); ++s) {
    const Volume raster = rasterize_mesh(surfaces[s], grid, 1.0f);
    for (std::size_t i = 0; i < raster.data.size(); ++i) {
      if (raster.data[i] == 0.0f) continue;
      if (owner[i] < 0) {
        owner[i] = static_cast<int>(s);
        continue;
      }
      auto& claimants = claims[i];
      if (claimants.empty()) claimants.push_back(owner[i]);
      claimants.push_back(static_cast<int>(s));
    }
  }
  map.labels.size = grid.size;
  map.labels.spacing = grid.spacing;
  map.labels.origin = grid.origin;
  map.labels.direction = grid.direction;
  map.labels.data.assign(grid.num_voxels(), 0.0f);
  settle_claims(claims, surfaces, map, owner);
  for (std::size_t i = 0; i < owner.size(); ++i) {
    if (owner[i] < 0) continue;
    map.labels.data[i] = static_cast<float>(values[owner[i]]);
    ++map.voxels[owner[i]];
  }
  return map;
}

}  // namespace mrsnake
