#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "mesh/image_io.h"
#include "tests/test_support.h"
#include "wavelets/model_io.h"

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

}  // namespace

TEST(BuildModelCli, BuildsAModelThatModelInfoAccepts) {
  const auto dir = scratch_dir("build-model-cli");
  const std::string labels = write_ellipsoid_labels(dir);
  const std::string model = (dir / "ellipsoid.model").string();
  const auto built = run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + model + " --faces 2048 --json");
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const nlohmann::json summary = nlohmann::json::parse(built.output);
  EXPECT_GE(summary["faces"].get<int>(), 1024);
  std::vector<std::string> stages;
  for (const auto& t : summary["timings"]) stages.push_back(t["stage"]);
  EXPECT_EQ(stages, (std::vector<std::string>{"read", "marching_cubes", "parameterization", "levels", "analysis", "report", "write"}));

  const ShapeModel m = load_model(model, {true});
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

  const auto info = run_mrsnake("model-info --json " + model);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_TRUE(nlohmann::json::parse(info.output)["synthesis"]["ok"].get<bool>());
}

TEST(BuildModelCli, BadInputsGetExitCodes) {
  const auto dir = scratch_dir("build-model-cli-bad");
  const std::string labels = write_ellipsoid_labels(dir);
  const std::string model = (dir / "m.model").string();
  const auto absent = run_mrsnake("-q build-model --labels " + labels + " --label 9 -o " + model);
  EXPECT_EQ(absent.exit_code, 3) << absent.output;
  EXPECT_FALSE(std::filesystem::exists(model));
  EXPECT_EQ(run_mrsnake("-q build-model --labels " + (dir / "none.nii.gz").string() + " --label 3 -o " + model).exit_code, 3);
  EXPECT_EQ(run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + model + " --predict cubic").exit_code, 2);
  EXPECT_EQ(run_mrsnake("-q build-model --labels " + labels + " --label 3 -o " + model + " --levels 3 --faces 100").exit_code, 2);
}
