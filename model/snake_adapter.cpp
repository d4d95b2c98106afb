#include "model/snake_adapter.h"

#include <memory>
#include <optional>

#include "mesh/errors.h"
#include "model/sections.h"
#include "snake/image_pyramid.h"
#include "wavelets/lifting.h"

namespace mrsnake {

namespace {
std::vector<RowMatrixX3d> model_levels(const ShapeModel& model) {
  if (static_cast<int>(model.level_positions.size()) == model.levels() + 1) return model.level_positions;
  std::vector<RowMatrixX3d> levels;
  for (int j = 0; j <= model.levels(); ++j) levels.push_back(synthesize(model, j));
  return levels;
}
}  // namespace

SnakeModel snake_model_from(const ShapeModel& model) {
  if (model.base.rows() == 0) throw InputError("the model has no base mesh", Remedy::rebuild_model);
  SnakeModel m;
  m.connectivity = model.connectivity();
  m.levels = model_levels(model);
  if (model.levels() > 0) {
    auto transform = std::make_shared<WaveletTransform>(m.connectivity, model.wavelet);
    auto details = std::make_shared<std::vector<RowMatrixX3d>>(model.details);
    m.synthesize = [transform, details](int j, const RowMatrixX3d& coarse) {
      return transform->synthesize_level(j, coarse, (*details)[j]);
    };
  } else {
    m.synthesize = [](int, const RowMatrixX3d& coarse) { return coarse; };
  }
  if (const auto it = model.sections.find(kAppearanceSection); it != model.sections.end())
    m.appearance = deserialize_appearance(it->second);
  if (const auto it = model.sections.find(kReferenceImageSection); it != model.sections.end())
    m.reference_image = deserialize_reference_image(it->second);
  return m;
}

ProfileAlignmentReport add_appearance(ShapeModel& model, const Volume& reference_image,
                                      const AppearanceOptions& options) {
  Volume normalized = reference_image;
  normalize_intensities(normalized);
  const std::vector<RowMatrixX3d> levels = model_levels(model);
  const SubdivisionConnectivity conn = model.connectivity();
  ProfileAlignmentReport alignment;
  const Appearance a = build_appearance(build_pyramid(normalized, 8), levels, conn.faces, options, &alignment);
  model.sections[kAppearanceSection] = serialize_appearance(a);
  return alignment;
}

std::vector<std::uint8_t> reference_image_section(const Volume& reference_image, const RowMatrixX3d& V,
                                                  const ReferenceImageOptions& options) {
  // The whole image's window, as segment normalizes a new image.
  const IntensityWindow window = robust_intensity_window(reference_image);
  Volume crop = make_reference_crop(reference_image, V, options);
  apply_intensity_window(crop, window);
  return serialize_reference_image(crop);
}

void add_reference_image(ShapeModel& model, const Volume& reference_image, const ReferenceImageOptions& options) {
  model.sections[kReferenceImageSection] =
      reference_image_section(reference_image, model_levels(model).back(), options);
}

std::vector<SnakeModel> snake_models_from(const ModelSet& set) {
  std::optional<Volume> shared;
  if (!set.reference_image.empty()) shared = deserialize_reference_image(set.reference_image);
  std::vector<SnakeModel> models;
  for (const ModelStructure& s : set.structures) {
    models.push_back(snake_model_from(s.model));
    if (shared) models.back().reference_image = shared;
  }
  return models;
}

}  // namespace mrsnake
