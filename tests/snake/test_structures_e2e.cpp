// A model of several structures end to end: build-model --label all with names, one segment
// for every structure, and the verdict on results made to fail.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "mesh/image_io.h"
#include "tests/test_support.h"

using namespace mrsnake;
using mrsnake::test::run_mrsnake;
namespace fs = std::filesystem;

namespace {

constexpr float kBackground = 100, kNoise = 8;

// Two ellipsoids (labels 3 and 7, on either side) and a thick ring (label 9, a wide tunnel
// through it: genus 1 after any closing allowed), moved by `shift` voxels and scaled by `grow`.
Volume scene_labels(double shift, double grow) {
  Volume v;
  v.size = {64, 48, 40};
  v.spacing = {0.5, 0.5, 0.5};
  v.origin = {-10, 4, 2};
  v.data.assign(v.num_voxels(), 0.0f);
  for (std::size_t k = 0; k < v.size[2]; ++k)
    for (std::size_t j = 0; j < v.size[1]; ++j)
      for (std::size_t i = 0; i < v.size[0]; ++i) {
        const double x = i - shift, y = j - 0.5 * shift, z = k;
        const auto e = [&](double cx, double cy, double cz, double rx, double ry, double rz) {
          const double a = (x - cx) / (grow * rx), b = (y - cy) / (grow * ry), c = (z - cz) / (grow * rz);
          return a * a + b * b + c * c <= 1.0;
        };
        const double ring = std::hypot(std::hypot(x - 32, z - 30) - 7.0, y - 38);
        if (e(17, 20, 17, 11, 8, 7))
          v.at(i, j, k) = 3;
        else if (e(46, 19, 18, 7, 9, 6))
          v.at(i, j, k) = 7;
        else if (ring <= 2.5)
          v.at(i, j, k) = 9;
      }
  return v;
}

// The scene's intensities: one per label over the background, with noise.
Volume scene_image(const Volume& labels, unsigned seed, double contrast = 1.0, double noise = kNoise) {
  Volume img = labels;
  std::mt19937 rng(seed);
  std::normal_distribution<float> gauss(0.0f, static_cast<float>(noise));
  for (std::size_t i = 0; i < img.data.size(); ++i) {
    const float l = labels.data[i];
    const float level = l == 3 ? 190.0f : l == 7 ? 150.0f : l == 9 ? 170.0f : kBackground;
    img.data[i] = kBackground + static_cast<float>(contrast) * (level - kBackground) + gauss(rng);
  }
  return img;
}

struct Scene {
  fs::path dir;
  std::string model;
  test::CommandResult build;  ///< build-model --label all --json, with its warnings
};

// The reference scene, its model of every label, and a new case beside it.
const Scene& built_scene() {
  static const Scene scene = [] {
    Scene s;
    s.dir = test::scratch_dir("structures-e2e");
    const Volume ref = scene_labels(0, 1.0);
    write_volume((s.dir / "ref_labels.nii.gz").string(), ref, VoxelType::uint8);
    write_volume((s.dir / "ref_image.nii.gz").string(), scene_image(ref, 1), VoxelType::float32);
    const Volume target = scene_labels(2.0, 1.06);
    write_volume((s.dir / "target_labels.nii.gz").string(), target, VoxelType::uint8);
    write_volume((s.dir / "target.nii.gz").string(), scene_image(target, 2), VoxelType::float32);
    std::ofstream(s.dir / "names.csv") << "value,name\n3,left body\n7,\"right body, small\"\n9,ring\n";
    s.model = (s.dir / "scene.model").string();
    const std::string d = s.dir.string();
    s.build = run_mrsnake("build-model --labels " + d + "/ref_labels.nii.gz --label all --label-names " + d +
                          "/names.csv --image " + d + "/ref_image.nii.gz -o " + s.model + " --json");
    return s;
  }();
  return scene;
}

nlohmann::json segment_json(const std::string& image, const std::string& out, const std::string& extra = "") {
  const Scene& s = built_scene();
  const auto r = run_mrsnake("-q segment --image " + image + " --model " + s.model + " -o " + out + extra);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  return r.exit_code == 0 ? nlohmann::json::parse(std::ifstream(out + "/report.json")) : nlohmann::json();
}

// The structure of `value` in report.json.
const nlohmann::json& structure(const nlohmann::json& rep, int value) {
  for (const nlohmann::json& s : rep["structures"])
    if (s["value"] == value) return s;
  static const nlohmann::json none;
  ADD_FAILURE() << "no structure " << value;
  return none;
}

}  // namespace

TEST(Structures, AllLabelsBuildOneModelAndSegmentIntoOneLabelMap) {
  const Scene& s = built_scene();
  const std::string d = s.dir.string();
  const test::CommandResult& b = s.build;
  ASSERT_EQ(b.exit_code, 0) << b.output;
  EXPECT_NE(b.output.find("skipped label 9 (ring)"), std::string::npos) << b.output;
  const auto info = run_mrsnake("model-info " + s.model + " --json");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const nlohmann::json mi = nlohmann::json::parse(info.output);
  ASSERT_EQ(mi["structures"].size(), 2u);
  EXPECT_EQ(mi["structures"][1]["name"], "right body, small");
  ASSERT_EQ(mi["skipped"].size(), 1u);
  EXPECT_EQ(mi["skipped"][0]["value"], 9);
  EXPECT_NE(mi["skipped"][0]["reason"].get<std::string>().find("genus"), std::string::npos) << mi["skipped"];
  EXPECT_TRUE(mi["shared_reference_image"].is_object());

  const nlohmann::json rep = segment_json(d + "/target.nii.gz", d + "/seg", " --truth " + d + "/target_labels.nii.gz");
  ASSERT_TRUE(rep.is_object());
  EXPECT_FALSE(rep["suspect"].get<bool>()) << rep["reason"];
  for (const int value : {3, 7}) {
    const nlohmann::json& st = structure(rep, value);
    EXPECT_GE(st["scores"]["dice"].get<double>(), 0.9) << value;
    EXPECT_FALSE(st["suspect"].get<bool>()) << st["reason"];
    EXPECT_TRUE(fs::is_regular_file(s.dir / "seg" / "surfaces" / (std::to_string(value) + ".vtp")));
  }
  // One label map with the reference's values; one registration for both.
  const Volume labels = read_volume(d + "/seg/labels.nii.gz");
  std::set<float> values(labels.data.begin(), labels.data.end());
  EXPECT_EQ(values, (std::set<float>{0, 3, 7}));
  EXPECT_TRUE(rep["stage_seconds"].contains("register"));
  EXPECT_FALSE(fs::exists(s.dir / "seg" / "surface.vtp"));  // only a model of one structure has it

  // A batch: one volume and one verdict column per structure.
  const auto batch = run_mrsnake("-q segment-batch --model " + s.model + " -o " + d + "/batch " + d + "/target.nii.gz");
  ASSERT_EQ(batch.exit_code, 0) << batch.output;
  std::ifstream csv(s.dir / "batch" / "batch.csv");
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  EXPECT_NE(header.find(",volume_mm3_3,suspect_3,volume_mm3_7,suspect_7"), std::string::npos) << header;
  EXPECT_NE(row.find(",false"), std::string::npos) << row;
}

TEST(Structures, AStructureErasedFromTheImageIsFlaggedAndTheOtherIsNot) {
  const Scene& s = built_scene();
  ASSERT_EQ(s.build.exit_code, 0) << s.build.output;
  Volume labels = scene_labels(2.0, 1.06);
  for (float& l : labels.data)
    if (l == 7) l = 0;  // filled with the surrounding intensity
  write_volume((s.dir / "erased.nii.gz").string(), scene_image(labels, 3), VoxelType::float32);
  const nlohmann::json rep = segment_json((s.dir / "erased.nii.gz").string(), (s.dir / "erased").string());
  ASSERT_TRUE(rep.is_object());
  EXPECT_TRUE(rep["suspect"].get<bool>());
  EXPECT_TRUE(structure(rep, 7)["suspect"].get<bool>());
  EXPECT_NE(structure(rep, 7)["reason"].get<std::string>().find("better than chance"), std::string::npos)
      << structure(rep, 7)["reason"];
  // The other still matches its image far better than chance.
  EXPECT_LT(structure(rep, 3)["quality_control"]["match_ratio"].get<double>(), 0.3);
  EXPECT_FALSE(structure(rep, 3)["suspect"].get<bool>()) << structure(rep, 3)["reason"];
}

TEST(Structures, ATenthOfTheContrastUnderHeavyNoiseIsFlagged) {
  const Scene& s = built_scene();
  ASSERT_EQ(s.build.exit_code, 0) << s.build.output;
  write_volume((s.dir / "faint.nii.gz").string(), scene_image(scene_labels(2.0, 1.06), 4, 0.1, 3 * kNoise),
               VoxelType::float32);
  const nlohmann::json rep = segment_json((s.dir / "faint.nii.gz").string(), (s.dir / "faint").string());
  ASSERT_TRUE(rep.is_object());
  EXPECT_TRUE(rep["suspect"].get<bool>()) << rep.dump(1).substr(0, 2000);
}

TEST(StructuresReal, ABrainModelOnTheAbdominalCtIsFlagged) {
  MRSNAKE_REQUIRE_DATA(mouse_labels, "volumes/mouse-brain/mouse1_labels.nii.gz");
  MRSNAKE_REQUIRE_DATA(mouse_image, "volumes/mouse-brain/mouse1_image.nii.gz");
  MRSNAKE_REQUIRE_DATA(ct, "volumes/abdomen-ct-small.nii.gz");
  const fs::path dir = test::scratch_dir("structures-brain-on-ct");
  const std::string model = (dir / "hippocampi.model").string();
  const auto b =
      run_mrsnake("-q build-model --labels " + mouse_labels + " --label 1,21 --image " + mouse_image + " -o " + model);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const auto s = run_mrsnake("-q segment --image " + ct + " --model " + model + " -o " + (dir / "seg").string());
  ASSERT_EQ(s.exit_code, 0) << s.output;  // flagged, not refused: the batch keeps its record
  const nlohmann::json rep = nlohmann::json::parse(std::ifstream(dir / "seg" / "report.json"));
  EXPECT_TRUE(rep["suspect"].get<bool>());
  for (const nlohmann::json& st : rep["structures"]) EXPECT_TRUE(st["suspect"].get<bool>()) << st["value"];
}

TEST(StructuresReal, ALiverModelOnTheCtFlippedLeftToRightIsFlagged) {
  MRSNAKE_REQUIRE_DATA(ct, "volumes/abdomen-ct-small.nii.gz");
  MRSNAKE_REQUIRE_DATA(labels, "volumes/abdomen-ct-small-seg.nii.gz");
  const fs::path dir = test::scratch_dir("structures-flipped-ct");
  const std::string model = (dir / "liver.model").string();
  const auto b = run_mrsnake("-q build-model --labels " + labels + " --label 5 --image " + ct + " -o " + model);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  // The liver lies on one side: flipped, the model's side holds the stomach and the spleen.
  Volume flipped = read_volume(ct);
  const Volume original = flipped;
  for (std::size_t k = 0; k < flipped.size[2]; ++k)
    for (std::size_t j = 0; j < flipped.size[1]; ++j)
      for (std::size_t i = 0; i < flipped.size[0]; ++i)
        flipped.at(i, j, k) = original.at(flipped.size[0] - 1 - i, j, k);
  write_volume((dir / "flipped.nii.gz").string(), flipped, VoxelType::float32);
  for (const auto& [image, suspect] :
       {std::pair<std::string, bool>{ct, false}, {(dir / "flipped.nii.gz").string(), true}}) {
    const auto s = run_mrsnake("-q segment --image " + image + " --model " + model + " -o " + (dir / "seg").string());
    ASSERT_EQ(s.exit_code, 0) << s.output;
    const nlohmann::json rep = nlohmann::json::parse(std::ifstream(dir / "seg" / "report.json"));
    EXPECT_EQ(rep["suspect"].get<bool>(), suspect) << image << ": " << rep["reason"];
  }
}
