#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/distance.h"
#include "mesh/image_io.h"
#include "tests/test_support.h"
#include "model/model_io.h"
#include "model/model_set.h"

using namespace mrsnake;
using namespace mrsnake::test;

namespace {

/// An ellipsoid of label 3 in a 40×36×32 grid of 1×1×1.25 mm voxels, away from the origin.
std::string write_ellipsoid_labels(const std::filesystem::path& dir) {
  Volume v;
  v.size = {40, 36, 32};
  v.spacing = {1.0, 1.0, 1.25};
  v.origin = {-12.0, 30.0, 5.0};
  v.data.assign(v.num_voxels(), 0.0f);
  for (std::size_t k = 0; k < v.size[2]; ++k)
    for (std::size_t j = 0; j < v.size[1]; ++j)
      for (std::size_t i = 0; i < v.size[0]; ++i) {
        const double x = (i - 19.5) / 15.0, y = (j - 17.5) / 12.0, z = (k - 15.5) / 10.0;
        if (x * x + y * y + z * z <= 1.0) v.at(i, j, k) = 3.0f;
      }
  const std::string path = (dir / "labels.nii.gz").string();
  write_volume(path, v, VoxelType::uint8);
  return path;
}

/// A label volume of `size` voxels of 1 mm at the origin: `label` where inside(x, y, z) holds
/// for the voxel's index, 0 elsewhere.
template <class Inside>
Volume labels_where(std::array<std::size_t, 3> size, float label, Inside inside) {
  Volume v;
  v.size = size;
  v.data.assign(v.num_voxels(), 0.0f);
  for (std::size_t k = 0; k < size[2]; ++k)
    for (std::size_t j = 0; j < size[1]; ++j)
      for (std::size_t i = 0; i < size[0]; ++i)
        if (inside(static_cast<double>(i), static_cast<double>(j), static_cast<double>(k))) v.at(i, j, k) = label;
  return v;
}

/// " --config FILE" for options given as JSON, written to dir/name.json.
std::string config_arg(const std::filesystem::path& dir, const std::string& name, const nlohmann::json& options) {
  const auto path = dir / (name + ".json");
  std::ofstream(path) << options.dump();
  return " --config " + path.string();
}

/// `mrsnake -q build-model ARGS` must exit with exit_code, say `mentions`, and leave no model at `model`.
void expect_refused(const std::string& args, int exit_code, const std::string& mentions, const std::string& model) {
  const auto r = run_mrsnake("-q build-model " + args);
  EXPECT_EQ(r.exit_code, exit_code) << args << "\n" << r.output;
  EXPECT_NE(r.output.find(mentions), std::string::npos) << args << "\n" << r.output;
  EXPECT_FALSE(std::filesystem::exists(model)) << args;
}

}  // namespace

TEST(BuildModelCli, BuildsAModelThatModelInfoAccepts) {
  const auto dir = scratch_dir("build-model-cli");
  const std::string labels = write_ellipsoid_labels(dir);
  const std::string model = (dir / "ellipsoid.model").string();
  const auto built =
      run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + model + " --faces 2048 --json");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const nlohmann::json summary = nlohmann::json::parse(built.output);
  EXPECT_GE(summary["faces"].get<int>(), 1024);
  std::vector<std::string> stages;
  for (const auto& t : summary["timings"]) stages.push_back(t["stage"]);
  EXPECT_EQ(stages, (std::vector<std::string>{"read", "marching_cubes", "parameterization", "levels", "analysis",
                                              "label_fit", "report", "write"}));

  const ShapeModel m = load_model_set(model, {true}).structures.at(0).model;
  EXPECT_EQ(m.source_label, 3);
  ASSERT_TRUE(m.physical_frame);
  EXPECT_EQ(m.physical_frame->spacing[2], 1.25);
  EXPECT_EQ(m.levels(), summary["levels"].get<int>());
  // The model lies where the labels are, in physical coordinates.
  const Eigen::RowVector3d center = m.level_positions.back().colwise().mean();
  EXPECT_NEAR(center.x(), -12.0 + 19.5, 1.0);
  EXPECT_NEAR(center.y(), 30.0 + 17.5, 1.0);
  EXPECT_NEAR(center.z(), 5.0 + 15.5 * 1.25, 1.0);
  EXPECT_TRUE(m.remesh_quality.contains("finest_level_quality"));
  // The finest level is checked for crossing faces: none on an ellipsoid, and no warning.
  EXPECT_EQ(m.remesh_quality["finest_level_self_intersections"].get<int>(),
            count_self_intersections(TriMesh{m.level_positions.back(), m.connectivity().faces.back()}));
  EXPECT_EQ(summary["finest_level_self_intersections"].get<int>(), 0);
  // The structure's size and every default derived from it are in model.json. The ellipsoid's
  // equivalent radius over 60 is below its 1 mm voxels: the voxels' own surface, smoothed 20 times.
  const nlohmann::json& scale = m.scale;
  ASSERT_TRUE(scale.is_object());
  const double radius = scale["equivalent_radius_mm"].get<double>();
  EXPECT_NEAR(4.0 / 3.0 * M_PI * radius * radius * radius, scale["volume_mm3"].get<double>(),
              1e-6 * radius * radius * radius);
  EXPECT_EQ(scale["finest_voxel_mm"].get<double>(), 1.0);
  EXPECT_LT(radius / 60.0, 1.0);
  EXPECT_EQ(summary["mc_spacing_mm"].get<double>(), 0.0);
  EXPECT_EQ(scale["marching_cubes_spacing_mm"].get<double>(), 0.0);
  EXPECT_EQ(m.remesh_quality["marching_cubes"]["spacing_mm"].get<double>(), 0.0);
  EXPECT_EQ(m.remesh_quality["marching_cubes"]["smoothing_iterations"].get<int>(), 20);
  EXPECT_EQ(scale["faces"].get<int>(), 2048);           // as given
  EXPECT_TRUE(scale["reference_margin_mm"].is_null());  // no --image
  // The finest level, rasterized on the label's grid, matches the label.
  EXPECT_GT(scale["fit_to_label"]["dice"].get<double>(), 0.95);
  EXPECT_NEAR(scale["fit_to_label"]["volume_ratio"].get<double>(), 1.0, 0.05);
  EXPECT_EQ(m.remesh_quality["marching_cubes"]["faces"].get<int>(), summary["input_faces"].get<int>());

  // A small surface takes the punctured sphere map by default.
  EXPECT_EQ(m.remesh_quality["parameterization"]["sphere_map"], "punctured");

  const auto info = run_mrsnake("model-info --json " + model);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(nlohmann::json::parse(info.output)["synthesis"]["ok"].get<bool>());

  // A model's vertices stay on the reference surface unless remesh.fit.rounds asks for the fit.
  EXPECT_EQ(m.remesh_quality["fit_rounds"].get<int>(), 0);
  EXPECT_FALSE(m.remesh_quality["per_level"].back().contains("fit"));

  // The sphere map and the fit rounds of a config reach the remesher and model.json records them.
  const std::string halves = (dir / "halves.model").string();
  const nlohmann::json config = {{"remesh", {{"sphere_map", "two_halves"}, {"fit", {{"rounds", 1}}}}}};
  const auto built_halves = run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + halves +
                                        " --faces 2048" + config_arg(dir, "halves", config));
  ASSERT_EQ(built_halves.exit_code, 0) << built_halves.output;
  const ShapeModel fitted = load_model_set(halves, {true}).structures.at(0).model;
  EXPECT_EQ(fitted.remesh_quality["parameterization"]["sphere_map"], "two_halves");
  EXPECT_EQ(fitted.remesh_quality["fit_rounds"].get<int>(), 1);
  EXPECT_TRUE(fitted.remesh_quality["per_level"].back().contains("fit"));
  EXPECT_EQ(fitted.build_options["remesh"]["fit"]["rounds"].get<int>(), 1);

  // The recorded options build the same model again, bit for bit.
  const std::string again = (dir / "again.model").string();
  const auto rebuilt = run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + again +
                                   config_arg(dir, "again", fitted.build_options));
  ASSERT_EQ(rebuilt.exit_code, 0) << rebuilt.output;
  EXPECT_EQ(read_all(std::filesystem::path(again) / "details.bin"),
            read_all(std::filesystem::path(halves) / "details.bin"));
}

// The mouse ventricles (label 10 of mouse 1) are thin sheets, and their model's finest level
// crosses itself with every default: the count is recorded, recounted equal, and warned of by name.
TEST(BuildModelCli, FlagsAModelWhoseFinestLevelPassesThroughItself) {
  MRSNAKE_REQUIRE_DATA(labels, "volumes/mouse-brain/mouse1_labels.nii.gz");
  const auto dir = scratch_dir("build-model-crossing");
  const std::string model = (dir / "ventricles.model").string();
  // With its spurs, the label's smoothed surface has needles that the finest level folds at.
  const auto built = run_mrsnake("-q build-model --labels " + labels + " --label 10 -o " + model +
                                 config_arg(dir, "spurs", {{"surface", {{"remove_spurs", false}}}}));
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const ShapeModel m = load_model_set(model, {true}).structures.at(0).model;
  const int crossings = m.remesh_quality["finest_level_self_intersections"].get<int>();
  EXPECT_EQ(crossings, count_self_intersections(TriMesh{m.level_positions.back(), m.connectivity().faces.back()}));
  ASSERT_GT(crossings, 0) << "the mouse ventricles' model no longer folds: take a harder input";
  EXPECT_NE(built.output.find("warning: label 10: the model's finest level passes through itself at " +
                              std::to_string(crossings) + " face pairs (model.json remesh_quality)"),
            std::string::npos)
      << built.output;
  std::filesystem::remove_all(dir);
}

TEST(BuildModelCli, McSpacingZeroUsesTheVoxelSurface) {
  const auto dir = scratch_dir("build-model-cli-spacing");
  const std::string labels = write_ellipsoid_labels(dir);
  const auto mc =
      run_mrsnake("-q mc --labels " + labels + " --label 3 -o " + (dir / "voxels.vtp").string() + " --json");
  ASSERT_EQ(mc.exit_code, 0) << mc.output;
  const int voxel_faces = nlohmann::json::parse(mc.output)["faces"].get<int>();
  const auto run = [&](const std::string& spacing) {
    const auto r =
        run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + (dir / ("m" + spacing)).string() +
                    " --faces 2048 --json" +
                    config_arg(dir, "spacing" + spacing, {{"surface", {{"mc_spacing_mm", std::stod(spacing)}}}}));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return nlohmann::json::parse(r.output);
  };
  EXPECT_EQ(run("0")["input_faces"].get<int>(), voxel_faces);  // exactly 'mrsnake mc''s surface
  const int coarse = run("2")["input_faces"].get<int>();
  EXPECT_LT(coarse * 2, voxel_faces);
  EXPECT_GT(coarse, 200);
  EXPECT_EQ(run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + (dir / "bad").string() +
                        config_arg(dir, "bad", {{"surface", {{"mc_spacing_mm", 1000}}}}))
                .exit_code,
            3);

  // A coarse image is not resampled: by default its voxels' own surface is used.
  Volume coarse_grid = read_volume(labels);
  coarse_grid.spacing = {2.5, 2.0, 3.0};
  const std::string coarse_labels = (dir / "coarse.nii.gz").string();
  write_volume(coarse_labels, coarse_grid, VoxelType::uint8);
  const auto built = run_mrsnake("-q build-model --labels " + coarse_labels + " --label 3 -o " +
                                 (dir / "coarse.model").string() + " --faces 2048 --json");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  EXPECT_EQ(nlohmann::json::parse(built.output)["mc_spacing_mm"].get<double>(), 0.0);
  const auto coarse_mc =
      run_mrsnake("-q mc --labels " + coarse_labels + " --label 3 -o " + (dir / "coarse.vtp").string() + " --json");
  ASSERT_EQ(coarse_mc.exit_code, 0) << coarse_mc.output;
  EXPECT_EQ(nlohmann::json::parse(built.output)["input_faces"].get<int>(),
            nlohmann::json::parse(coarse_mc.output)["faces"].get<int>());
}

TEST(BuildModelCli, BadInputsGetExitCodes) {
  const auto dir = scratch_dir("build-model-cli-bad");
  const std::string labels = write_ellipsoid_labels(dir);
  const std::string model = (dir / "m.model").string();
  const auto absent = run_mrsnake("-q build-model --labels " + labels + " --label 9 -o " + model);
  EXPECT_EQ(absent.exit_code, 3) << absent.output;
  EXPECT_FALSE(std::filesystem::exists(model));
  EXPECT_EQ(
      run_mrsnake("-q build-model --labels " + (dir / "none.nii.gz").string() + " --label 3 -o " + model).exit_code, 3);
  expect_refused(
      "--labels " + labels + " --label 3 -o " + model + config_arg(dir, "cubic", {{"wavelet", {{"predict", "cubic"}}}}),
      3, "\"linear\", \"butterfly\"", model);
  EXPECT_EQ(run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + (dir / "faces.model").string() +
                        " --faces 100" + config_arg(dir, "levels", {{"levels", 3}, {"faces", 200}}))
                .exit_code,
            0);  // --faces replaces the file's levels
  expect_refused(
      "--labels " + labels + " --label 3 -o " + model + config_arg(dir, "both", {{"levels", 3}, {"faces", 200}}), 3,
      "faces", model);
  expect_refused("--labels " + labels + " --label 3 -o " + model + " --image " + labels +
                     config_arg(dir, "middle", {{"appearance", {{"alignment", "middle"}}}}),
                 3, "alignment", model);
  expect_refused("--labels " + labels + " --label 3 -o " + model + config_arg(dir, "typo", {{"surfaces", 1}}), 3,
                 "unknown options key 'surfaces'", model);
  expect_refused("--labels " + labels + " --label 3 -o " + model + " --faces 100 --levels 3", 2, "--levels", model);
}

TEST(BuildModelCli, ProfileAlignmentIsChosenAndReported) {
  // The label volume as its own image: a clean step, so `auto` centres the profiles on its edges.
  const auto dir = scratch_dir("build-model-cli-alignment");
  const std::string labels = write_ellipsoid_labels(dir);
  const auto summary_of = [&](const std::string& name, const std::string& extra) {
    const auto r = run_mrsnake("-q build-model --labels " + labels + " --label 3 --image " + labels + " -o " +
                               (dir / name).string() + " --faces 2048 --json" + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return nlohmann::json::parse(r.output)["profile_alignment"];
  };
  const nlohmann::json automatic = summary_of("auto.model", ""),
                       labels_kept = summary_of("labels.model",
                                                config_arg(dir, "labels", {{"appearance", {{"alignment", "labels"}}}}));
  EXPECT_EQ(automatic["centred_on"], "edges");
  EXPECT_GE(automatic["levels_aligned"].get<int>(), 1);
  EXPECT_GT(automatic["mean_abs_shift_mm"].get<double>(), 0.0);
  EXPECT_LE(automatic["mean_abs_shift_mm"].get<double>(), 0.5 * 1.25 + 1e-9);  // half the largest voxel side
  EXPECT_LT(automatic["step_residual"].get<double>(), 0.5);
  EXPECT_EQ(labels_kept["centred_on"], "labels");
  EXPECT_EQ(labels_kept["levels_aligned"].get<int>(), 0);
  EXPECT_EQ(labels_kept["step_residual"], automatic["step_residual"]);
  // The model keeps, per level, where its profiles sit (segment deforms the levels finer than
  // the image only when they sit on the edges), and model-info shows it.
  const auto centred_on = [&](const std::string& name) {
    const auto r = run_mrsnake("model-info --json " + (dir / name).string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json info = nlohmann::json::parse(r.output);
    std::vector<std::string> where;
    for (const auto& c : info["appearance"]["profiles_centred_on"]) where.push_back(c.get<std::string>());
    return where;
  };
  const std::vector<std::string> aligned = centred_on("auto.model"), kept = centred_on("labels.model");
  ASSERT_FALSE(aligned.empty());
  EXPECT_EQ(std::count(aligned.begin(), aligned.end(), "edges"), automatic["levels_aligned"].get<int>());
  EXPECT_EQ(aligned.back(), "edges");  // the finest level is sampled at full resolution
  EXPECT_EQ(kept, std::vector<std::string>(aligned.size(), "labels"));
  const auto text = run_mrsnake("model-info " + (dir / "auto.model").string());
  EXPECT_NE(text.output.find("centred on labels"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find(" edges (levels 0.."), std::string::npos) << text.output;
  std::filesystem::remove_all(dir);
}

TEST(BuildModelCli, CloseTunnelsMakesAGenusOneLabelModelable) {
  // A torus (major radius 9, minor 5.5 voxels; its hole has radius 3.5): genus 1, which the
  // remesher refuses, unless --close-tunnels fills the hole first.
  const auto dir = scratch_dir("build-model-cli-torus");
  const Volume v = labels_where({40, 40, 40}, 4.0f, [](double i, double j, double k) {
    const double ring = std::hypot(i - 19.5, j - 19.5) - 9.0;
    return ring * ring + (k - 19.5) * (k - 19.5) <= 5.5 * 5.5;
  });
  const std::string labels = (dir / "torus.nii.gz").string();
  write_volume(labels, v, VoxelType::uint8);
  const std::string model = (dir / "torus.model").string();

  // Refused before the remeshing, with the flag that repairs it.
  const auto refused =
      run_mrsnake("-q build-model --labels " + labels + " --label 4 -o " + model + " --faces 2048 --close-tunnels 0");
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  EXPECT_NE(
      refused.output.find("genus-1 surface (tunnels through it), but a model needs genus 0; drop --close-tunnels 0 "),
      std::string::npos)
      << refused.output;
  // The default closes tunnels up to 3 voxels: this hole is wider, and it says so.
  expect_refused("--labels " + labels + " --label 4 -o " + model + " --faces 2048", 3,
                 "a closing of radius up to 3 voxels did not remove them: try a larger --close-tunnels", model);
  EXPECT_FALSE(std::filesystem::exists(model));
  // Too small a radius leaves the tunnel open: still refused, with a hint.
  expect_refused("--labels " + labels + " --label 4 -o " + model + " --faces 2048 --close-tunnels 1", 3,
                 "try a larger --close-tunnels", model);

  const auto built = run_mrsnake("-q build-model --labels " + labels + " --label 4 -o " + model +
                                 " --faces 2048 --close-tunnels 6 --json");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  // The repair is announced (a warning on stderr, before the JSON on stdout).
  EXPECT_NE(built.output.find("closed its tunnels"), std::string::npos) << built.output;
  const nlohmann::json summary = nlohmann::json::parse(built.output.substr(built.output.find('{')));
  EXPECT_GE(summary["closing_radius_voxels"].get<int>(), 1);
  EXPECT_LE(summary["closing_radius_voxels"].get<int>(), 6);
  const ShapeModel m = load_model_set(model, {true}).structures.at(0).model;
  EXPECT_EQ(m.levels(), summary["levels"].get<int>());
}

namespace {

/// A capsule of label 1 along x: radius `radius` voxels, `length` voxels between the centres of
/// its caps, in a grid 20 voxels longer and 24 voxels across.
std::string write_tube_labels(const std::filesystem::path& dir, int length, double radius) {
  const Volume v =
      labels_where({static_cast<std::size_t>(length) + 20, 24, 24}, 1.0f, [&](double i, double j, double k) {
        const double x = i - std::clamp(i, 10.0, 10.0 + length), y = j - 11.5, z = k - 11.5;
        return x * x + y * y + z * z <= radius * radius;
      });
  const std::string path = (dir / ("tube" + std::to_string(length) + ".nii.gz")).string();
  write_volume(path, v, VoxelType::uint8);
  return path;
}

}  // namespace

TEST(BuildModelCli, LongTubesArePuncturedInTheMiddleAndTheTooLongBuiltOnTheBaseMesh) {
  // A one-chart sphere map squeezes a tube's far end exponentially in its length over its
  // radius. Punctured near the middle, a 70-voxel tube of radius 2.5 stays within the limit
  // (12 orders of magnitude) and keeps the conformal map. A 100-voxel one does not: squeezed,
  // it is built on the base-mesh domain alone (the hierarchical sphere map only if that
  // failed), with no flipped triangle at any level.
  const auto dir = scratch_dir("build-model-cli-tube");
  const std::string model = (dir / "tube.model").string();
  const auto built =
      run_mrsnake("-q build-model --labels " + write_tube_labels(dir, 70, 2.5) + " --label 1 -o " + model +
                  " --faces 2048 --json" + config_arg(dir, "mc12", {{"surface", {{"mc_spacing_mm", 1.2}}}}));
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const auto summary = nlohmann::json::parse(built.output);
  EXPECT_EQ(summary["faces"], 2048);
  EXPECT_GT(summary["finest_level_quality"]["min_angle_deg"].get<double>(), 25.0);
  EXPECT_EQ(load_model_set(model, {true}).structures.at(0).model.remesh_quality["parameterization"]["sphere_map"],
            "punctured");
  std::filesystem::remove_all(model);

  const auto r = run_mrsnake("-q build-model --labels " + write_tube_labels(dir, 100, 2.5) + " --label 1 -o " + model +
                             " --faces 2048" + config_arg(dir, "mc12", {{"surface", {{"mc_spacing_mm", 1.2}}}}));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const ShapeModel long_tube = load_model_set(model, {true}).structures.at(0).model;
  const nlohmann::json& choice = long_tube.remesh_quality["parameterization"]["domain_choice"];
  EXPECT_NE(choice.value("sphere_map_fallback", std::string()).find("orders of magnitude"), std::string::npos)
      << choice;
  EXPECT_TRUE(choice["base_mesh"].contains("q_mean")) << choice;
  EXPECT_TRUE(choice["sphere"].contains("skipped")) << choice;  // squeezed: the base mesh alone
  EXPECT_EQ(choice["chosen"], "base_mesh");
  EXPECT_EQ(long_tube.remesh_quality["domain"], choice["chosen"]);
  for (const auto& level : long_tube.remesh_quality["per_level"]) EXPECT_EQ(level["flipped_triangles"], 0) << level;
  std::filesystem::remove_all(dir);
}

TEST(BuildModelCli, ComponentModelsOnePartOfALabelAndRecordsIt) {
  // Label 3 on two balls, like a left and a right organ under one label: radius 7 about
  // voxel (10, 12, 12) and radius 5 about (30, 12, 12).
  const auto dir = scratch_dir("build-model-cli-parts");
  const Volume v = labels_where({42, 24, 24}, 3.0f, [](double i, double j, double k) {
    const double y = j - 12.0, z = k - 12.0, left = i - 10.0, right = i - 30.0;
    return left * left + y * y + z * z <= 49.0 || right * right + y * y + z * z <= 25.0;
  });
  const std::string labels = (dir / "two.nii.gz").string();
  write_volume(labels, v, VoxelType::uint8);

  // Without --component: the largest, with a warning that names the option.
  const std::string whole = (dir / "whole.model").string();
  const auto w = run_mrsnake("build-model --labels " + labels + " --label 3 -o " + whole + " --faces 512");
  ASSERT_EQ(w.exit_code, 0) << w.output;
  EXPECT_NE(
      w.output.find("2 connected surfaces; the model uses the largest (--component K models the K-th largest part"),
      std::string::npos)
      << w.output;
  EXPECT_FALSE(load_model_set(whole, {true}).structures.at(0).model.source_component.has_value());

  for (const int part : {1, 2}) {
    const std::string model = (dir / ("part" + std::to_string(part) + ".model")).string();
    const auto r = run_mrsnake("build-model --labels " + labels + " --label 3 --component " + std::to_string(part) +
                               " -o " + model + " --faces 512");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("connected surfaces"), std::string::npos) << r.output;  // one part: nothing dropped
    const ShapeModel m = load_model_set(model, {true}).structures.at(0).model;
    EXPECT_EQ(m.source_component, part);
    const Eigen::RowVector3d centre = m.level_positions.back().colwise().mean();
    EXPECT_NEAR(centre.x(), part == 1 ? 10.0 : 30.0, 0.5);
    EXPECT_NEAR(centre.y(), 12.0, 0.5);
    const double radius = (m.level_positions.back().rowwise() - centre).rowwise().norm().mean();
    EXPECT_NEAR(radius, part == 1 ? 7.0 : 5.0, 0.6);
    const auto info = run_mrsnake("model-info " + model);
    EXPECT_NE(info.output.find("label 3, its part " + std::to_string(part) + " by size"), std::string::npos)
        << info.output;
  }
  expect_refused("--labels " + labels + " --label 3 --component 3 -o " + (dir / "part3.model").string(), 3,
                 "label 3 has 2 connected parts, so there is no part 3; give --component 1 to 2",
                 (dir / "part3.model").string());
  std::filesystem::remove_all(dir);
}

TEST(BuildModelCli, AModelThatLostItsOrganIsRefusedUnlessAllowed) {
  // A ball of radius 12 voxels of 0.15 mm (1.8 mm, a mouse structure's size): a marching-cubes
  // grid of 1.2 mm, a human organ's, leaves a blob of a few cells whose rasterized finest
  // level misses most of the label. Refused with exit 5, naming the option that fixes it.
  const auto dir = scratch_dir("build-model-cli-poor-fit");
  Volume v = labels_where({32, 32, 32}, 1.0f, [](double i, double j, double k) {
    const double x = i - 15.5, y = j - 15.5, z = k - 15.5;
    return x * x + y * y + z * z <= 144.0;
  });
  v.spacing = {0.15, 0.15, 0.15};
  const std::string labels = (dir / "ball.nii.gz").string();
  write_volume(labels, v, VoxelType::uint8);
  const std::string model = (dir / "ball.model").string();
  expect_refused("--labels " + labels + " --label 1 -o " + model +
                     config_arg(dir, "mc12", {{"surface", {{"mc_spacing_mm", 1.2}}}}),
                 5, "the model's finest level covers its label with Dice ", model);
  const auto refused = run_mrsnake("-q build-model --labels " + labels + " --label 1 -o " + model +
                                   config_arg(dir, "mc12", {{"surface", {{"mc_spacing_mm", 1.2}}}}));
  EXPECT_NE(refused.output.find("give a smaller surface.mc_spacing_mm with --config (e.g. 0.15)"), std::string::npos)
      << refused.output;
  EXPECT_NE(refused.output.find("--allow-poor-fit"), std::string::npos) << refused.output;

  // Allowed: written, with a warning and the fit in model.json.
  const auto allowed =
      run_mrsnake("-q build-model --labels " + labels + " --label 1 -o " + model +
                  config_arg(dir, "mc12", {{"surface", {{"mc_spacing_mm", 1.2}}}}) + " --allow-poor-fit");
  ASSERT_EQ(allowed.exit_code, 0) << allowed.output;
  EXPECT_NE(allowed.output.find("warning: the model's finest level covers its label with Dice "), std::string::npos)
      << allowed.output;
  const ShapeModel poor = load_model_set(model, {true}).structures.at(0).model;
  EXPECT_LT(poor.scale["fit_to_label"]["dice"].get<double>(), 0.9);
  std::filesystem::remove_all(model);

  // The defaults, derived from the ball and its voxels, keep it.
  const auto built = run_mrsnake("-q build-model --labels " + labels + " --label 1 -o " + model + " --json");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const auto summary = nlohmann::json::parse(built.output);
  EXPECT_GT(summary["scale"]["fit_to_label"]["dice"].get<double>(), 0.95);
  EXPECT_NEAR(summary["scale"]["equivalent_radius_mm"].get<double>(), 1.8, 0.05);
  // model-info shows the structure's size and the fit.
  const auto info = run_mrsnake("model-info " + model);
  EXPECT_NE(info.output.find("equivalent radius 1.8"), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("fit to its label  Dice "), std::string::npos) << info.output;
  std::filesystem::remove_all(dir);
}
