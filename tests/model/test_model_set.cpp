// Models of many structures on disk (model/model_set.h) and label names (model/label_names.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "model/label_names.h"
#include "model/model_set.h"
#include "tests/test_support.h"
#include "tests/wavelets/hierarchies.h"

using namespace mrsnake;
using namespace mrsnake::test;
namespace fs = std::filesystem;

namespace {

ShapeModel small_model(double scale) {
  const Hierarchy h = bumpy_sphere(2);
  ShapeModel m = make_model(h.conn, scale * h.finest);
  m.sections["appearance"] = {1, 2, 3};
  return m;
}

ModelSet two_structures() {
  ModelSet set;
  set.source_image = "atlas-labels.nii.gz";
  set.structures.push_back({3, LabelName{"caudate", {10, 20, 30}}, small_model(1.0)});
  set.structures.push_back({7, LabelName{"thalamus, left", {200, 100, 0}}, small_model(2.0)});
  set.skipped.push_back({9, "fornix", "label 9 has a genus-2 surface"});
  set.reference_image = {9, 8, 7, 6, 5};
  set.build_options = {{"faces", 0}};
  return set;
}

void write_text(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

std::string input_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(ModelSet, SavesAndLoadsEveryStructureWithItsNameAndTheSharedCrop) {
  const fs::path dir = scratch_dir("model-set") / "two.model";
  save_model_set(dir.string(), two_structures());
  EXPECT_TRUE(fs::is_regular_file(dir / "structures" / "3" / "model.json"));
  EXPECT_TRUE(fs::is_regular_file(dir / "reference_image.bin"));
  const ModelSet set = load_model_set(dir.string(), {true});
  EXPECT_EQ(set.format_version, 2);
  ASSERT_EQ(set.structures.size(), 2u);
  EXPECT_EQ(set.structures[1].value, 7);
  EXPECT_EQ(set.structures[1].label.name, "thalamus, left");
  EXPECT_EQ(set.structures[1].label.color, (std::array<int, 3>{200, 100, 0}));
  EXPECT_EQ(set.structures[0].model.base, two_structures().structures[0].model.base);  // bit for bit
  EXPECT_EQ(set.structures[1].model.level_positions.back().rows(),
            set.structures[0].model.level_positions.back().rows());
  EXPECT_EQ(set.reference_image, (std::vector<std::uint8_t>{9, 8, 7, 6, 5}));
  ASSERT_EQ(set.skipped.size(), 1u);
  EXPECT_EQ(set.skipped[0].reason, "label 9 has a genus-2 surface");
  EXPECT_EQ(set.source_image, "atlas-labels.nii.gz");
  // One structure's folder is not the model: load_model says what it is.
  EXPECT_NE(input_error([&] { load_model(dir.string()); }).find("is a model of structures"), std::string::npos);
}

TEST(ModelSet, AFolderOfOneStructureReadsAsAModelOfThatStructure) {
  const fs::path dir = scratch_dir("model-set-v1") / "one.model";
  ShapeModel m = small_model(1.0);
  m.source_label = 255;
  save_model(dir.string(), m);
  const ModelSet set = load_model_set(dir.string());
  EXPECT_EQ(set.format_version, 1);
  ASSERT_EQ(set.structures.size(), 1u);
  EXPECT_EQ(set.structures[0].value, 255);
  EXPECT_EQ(set.structures[0].label.name, "label 255");
}

TEST(ModelSet, AStructureSwappedOrAPartAlteredIsRefused) {
  const fs::path root = scratch_dir("model-set-tamper");
  const fs::path a = root / "a.model", b = root / "b.model";
  ModelSet other = two_structures();
  other.structures[0].model = small_model(1.5);
  save_model_set(a.string(), two_structures());
  save_model_set(b.string(), other);
  // Structure 3 of another model in place of this one's: its manifest's checksum differs.
  fs::remove_all(a / "structures" / "3");
  fs::copy(b / "structures" / "3", a / "structures" / "3", fs::copy_options::recursive);
  EXPECT_NE(input_error([&] { load_model_set(a.string()); }).find("is not the one its manifest lists"),
            std::string::npos);
  write_text(b / "reference_image.bin", "xxxxx");
  EXPECT_NE(input_error([&] { load_model_set(b.string()); }).find("altered or corrupted"), std::string::npos);
}

TEST(LabelNames, ReadsAnItkSnapDescriptionAndACsvAndRefusesMalformedRows) {
  const fs::path dir = scratch_dir("label-names");
  write_text(dir / "snap.txt",
             "################################################\n"
             "# ITK-SnAP Label Description File\n"
             "#    IDX   -R-  -G-  -B-  -A--  VIS MSH  LABEL\n"
             "    0     0    0    0        0  0  0    \"Clear Label\"\n"
             "    3   255  128    0        1  1  1    \"Caudate putamen\"\n"
             "   21     0   64  255      0.5  1  0    \"Hippocampus (B)\"\n");
  const auto snap = read_label_names((dir / "snap.txt").string());
  ASSERT_EQ(snap.size(), 3u);
  EXPECT_EQ(snap.at(3).name, "Caudate putamen");
  EXPECT_EQ(snap.at(3).color, (std::array<int, 3>{255, 128, 0}));
  EXPECT_EQ(snap.at(21).name, "Hippocampus (B)");

  write_text(dir / "names.csv",
             "value,structure,side\n1,Hippocampus,A\n2,\"External capsule, corpus callosum\",both\n");
  const auto csv = read_label_names((dir / "names.csv").string());
  ASSERT_EQ(csv.size(), 2u);
  EXPECT_EQ(csv.at(2).name, "External capsule, corpus callosum");
  EXPECT_EQ(csv.at(1).color, default_label_color(1));
  EXPECT_NE(default_label_color(1), default_label_color(2));

  write_text(dir / "bad.csv", "value,name\n1,a\nx,b\n");
  EXPECT_NE(input_error([&] { read_label_names((dir / "bad.csv").string()); }).find("line 3"), std::string::npos);
  write_text(dir / "twice.csv", "1,a\n1,b\n");
  EXPECT_NE(input_error([&] { read_label_names((dir / "twice.csv").string()); }).find("twice"), std::string::npos);
  write_text(dir / "empty.csv", "# nothing\n");
  EXPECT_NE(input_error([&] { read_label_names((dir / "empty.csv").string()); }).find("hold no row"),
            std::string::npos);
}
