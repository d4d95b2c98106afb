// build_model(): the offline pipeline as a library function, without the command line.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "model/build_model.h"
#include "model/snake_adapter.h"
#include "snake/reference_image.h"

using namespace mrsnake;

namespace {

// Voxels of 1 × 1 × 1.25 mm away from the origin; `value` inside the ellipsoid with the given
// centre and semi-axes (in voxels), `background` elsewhere.
Volume ellipsoid(float value, float background, double ca, double cb, double cc, double ra, double rb, double rc) {
  Volume v;
  v.size = {40, 36, 32};
  v.spacing = {1.0, 1.0, 1.25};
  v.origin = {-12.0, 30.0, 5.0};
  v.data.assign(v.num_voxels(), background);
  for (std::size_t k = 0; k < v.size[2]; ++k)
    for (std::size_t j = 0; j < v.size[1]; ++j)
      for (std::size_t i = 0; i < v.size[0]; ++i) {
        const double x = (i - ca) / ra, y = (j - cb) / rb, z = (k - cc) / rc;
        if (x * x + y * y + z * z <= 1.0) v.at(i, j, k) = value;
      }
  return v;
}

Volume ellipsoid_labels() { return ellipsoid(3.0f, 0.0f, 19.5, 17.5, 15.5, 15.0, 12.0, 10.0); }

// A ring of label 2: a torus of tube radius 4 voxels around a circle of radius 10 voxels.
Volume ring_labels() {
  Volume v = ellipsoid(0.0f, 0.0f, 0, 0, 0, 1, 1, 1);
  for (std::size_t k = 0; k < v.size[2]; ++k)
    for (std::size_t j = 0; j < v.size[1]; ++j)
      for (std::size_t i = 0; i < v.size[0]; ++i) {
        const double x = i - 19.5, y = j - 17.5, z = k - 15.5;
        const double d = std::hypot(x, y) - 10.0;
        if (d * d + z * z <= 16.0) v.at(i, j, k) = 2.0f;
      }
  return v;
}

BuildModelOptions small_model(int label) {
  BuildModelOptions o;
  o.label = label;
  o.faces = 1280;
  return o;
}

std::vector<std::string> stage_names(const BuiltModel& built) {
  std::vector<std::string> names;
  for (const auto& [stage, seconds] : built.timings) {
    names.push_back(stage);
    EXPECT_GE(seconds, 0.0) << stage;
  }
  return names;
}

}  // namespace

TEST(BuildModel, AnEllipsoidGivesANestedModelThatCoversItsLabel) {
  const Volume labels = ellipsoid_labels();
  const BuiltModel built = build_model(labels, nullptr, small_model(3));
  const ShapeModel& m = built.model;
  const SubdivisionConnectivity conn = m.connectivity();
  ASSERT_GE(m.levels(), 1);
  // The stored base faces and L rebuild the hierarchy's connectivity exactly.
  EXPECT_EQ(conn.vertex_counts, built.hierarchy.connectivity.vertex_counts);
  EXPECT_EQ(conn.faces.back().rows(), m.base_faces.rows() << (2 * m.levels()));
  // The synthesis of the stored details gives back the finest level the analysis saw.
  const RowMatrixX3d finest = synthesize(m);
  EXPECT_LT((finest - built.hierarchy.levels.back().positions).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_GE(built.fit.dice, kMinLabelFitDice);
  EXPECT_NEAR(built.fit.volume_ratio, 1.0, 0.05);
  // The model records where it came from, in the label image's frame.
  ASSERT_TRUE(m.physical_frame.has_value());
  EXPECT_EQ(m.physical_frame->size, labels.size);
  EXPECT_EQ(m.physical_frame->origin, labels.origin);
  EXPECT_EQ(m.source_label, 3);
  EXPECT_FALSE(m.source_component.has_value());
  EXPECT_EQ(m.scale["faces"].get<int>(), conn.faces.back().rows());
  EXPECT_EQ(m.scale["marching_cubes_spacing_mm"].get<double>(), built.mc_spacing_mm);
  EXPECT_TRUE(m.scale["reference_margin_mm"].is_null());
  EXPECT_TRUE(m.sections.empty());
  EXPECT_EQ(stage_names(built),
            (std::vector<std::string>{"marching_cubes", "parameterization", "levels", "analysis", "label_fit"}));
}

TEST(BuildModel, AnImageAddsTheAppearanceAndTheReferenceCrop) {
  const Volume labels = ellipsoid_labels();
  const Volume image = ellipsoid(200.0f, 40.0f, 19.5, 17.5, 15.5, 15.0, 12.0, 10.0);
  const BuiltModel built = build_model(labels, &image, small_model(3));
  EXPECT_EQ(built.model.sections.count(kAppearanceSection), 1u);
  EXPECT_EQ(built.model.sections.count(kReferenceImageSection), 1u);
  ASSERT_TRUE(built.reference_margin_mm.has_value());
  EXPECT_EQ(*built.reference_margin_mm, default_reference_margin(built.scale));
  EXPECT_TRUE(built.alignment.has_value());
  // The snake reads both sections back.
  const SnakeModel snake = snake_model_from(built.model);
  EXPECT_TRUE(snake.appearance.has_value());
  EXPECT_TRUE(snake.reference_image.has_value());
  EXPECT_EQ(stage_names(built).back(), "appearance");
}

TEST(BuildModel, OneComponentOfALabelIsModelledAlone) {
  // Two ellipsoids of label 3: the larger on the left, the smaller on the right.
  Volume labels = ellipsoid(3.0f, 0.0f, 11.0, 17.5, 15.5, 8.0, 9.0, 8.0);
  const Volume small = ellipsoid(3.0f, 0.0f, 31.0, 17.5, 15.5, 5.0, 6.0, 5.0);
  for (std::size_t v = 0; v < labels.data.size(); ++v) labels.data[v] = std::max(labels.data[v], small.data[v]);
  BuildModelOptions o = small_model(3);
  o.component = 2;
  const BuiltModel built = build_model(labels, nullptr, o);
  EXPECT_EQ(built.model.source_component, 2);
  EXPECT_GE(built.fit.dice, kMinLabelFitDice);
  // Its finest level lies around the small part's centre, x = -12 + 31 mm.
  EXPECT_NEAR(built.hierarchy.levels.back().positions.col(0).mean(), 19.0, 1.0);
}

TEST(BuildModel, ATunnelIsClosedOrRefusedAsTheOptionsSay) {
  const Volume ring = ring_labels();
  BuildModelOptions refuse = small_model(2);
  refuse.surface.close_tunnels = 0;
  try {
    build_model(ring, nullptr, refuse);
    FAIL() << "a ring has genus 1";
  } catch (const LabelGenusError& e) {
    EXPECT_EQ(e.genus, 1);
    EXPECT_NE(std::string(e.what()).find("genus-1"), std::string::npos) << e.what();
    // The library says what is wrong; the command adds what to type.
    EXPECT_EQ(std::string(e.what()).find("--"), std::string::npos) << e.what();
  }
}

TEST(BuildModel, APoorFitIsRefusedUnlessAllowed) {
  // Marching cubes at 6 mm loses most of a structure of radius ~12 mm.
  BuildModelOptions coarse = small_model(3);
  coarse.surface.mc_spacing_mm = 6.0;
  const Volume labels = ellipsoid_labels();
  try {
    build_model(labels, nullptr, coarse);
    FAIL() << "a 6 mm surface should not cover the label";
  } catch (const PoorFitError& e) {
    EXPECT_LT(e.fit.dice, kMinLabelFitDice);
    EXPECT_EQ(e.mc_spacing_mm, 6.0);
    EXPECT_EQ(std::string(e.what()), describe_poor_fit(e.fit));
  }
  coarse.allow_poor_fit = true;
  const BuiltModel kept = build_model(labels, nullptr, coarse);
  EXPECT_LT(kept.fit.dice, kMinLabelFitDice);
}

TEST(BuildModel, ThePresetKeepsTheVerticesOnTheReferenceSurface) {
  const RemeshOptions preset = model_remesh_preset();
  EXPECT_EQ(preset.fit.rounds, 0);
  EXPECT_EQ(BuildModelOptions{}.remesh.fit.rounds, 0);
  EXPECT_GT(preset.sizing.curvature_weight, RemeshOptions{}.sizing.curvature_weight);
}

TEST(BuildModel, OptionsOutOfRangeOrOverwrittenAreRefusedBeforeAnyWork) {
  // The resolution is the top-level faces or levels; remesh's own keys would be overwritten.
  const Volume labels = ellipsoid_labels();
  BuildModelOptions o = small_model(3);
  o.remesh.target_faces = 5000;
  EXPECT_THROW(build_model(labels, nullptr, o), OptionsError);
  o = small_model(3);
  o.remesh.levels = 2;
  EXPECT_THROW(build_model(labels, nullptr, o), OptionsError);
  // The remesh options' own ranges hold too.
  o = small_model(3);
  o.remesh.relaxation.lloyd_iterations = -1;
  try {
    validate(o);
    ADD_FAILURE() << "accepted";
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("remesh.relaxation.lloyd_iterations"), std::string::npos) << e.what();
  }
  o = small_model(3);
  o.surface.close_tunnels = 40;
  try {
    build_model(labels, nullptr, o);
    ADD_FAILURE() << "accepted";
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("surface.close_tunnels"), std::string::npos) << e.what();
  }
}
