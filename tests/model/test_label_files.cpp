// The files that name a label map's values for 3D Slicer and ITK-SNAP (model/label_files.h).
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "model/label_files.h"

namespace {

// 4x3x2 voxels: value 2 over i 1..2, j 0..1, k 1; value 5 at (3, 2, 0).
mrsnake::Volume two_values() {
  mrsnake::Volume v;
  v.size = {4, 3, 2};
  v.data.assign(v.num_voxels(), 0.f);
  for (int i = 1; i <= 2; ++i)
    for (int j = 0; j <= 1; ++j) v.at(i, j, 1) = 2;
  v.at(3, 2, 0) = 5;
  return v;
}

std::map<std::string, std::string> as_map(const std::vector<std::pair<std::string, std::string>>& fields) {
  return {fields.begin(), fields.end()};
}

}  // namespace

TEST(LabelFiles, SlicerSegmentsCarryTheirNamesColoursValuesAndExtents) {
  const std::vector<mrsnake::NamedValue> values = {
      {2, {"left \"cortex\"", {255, 0, 0}}}, {5, {"b", {0, 51, 255}}}, {7, {"absent", {1, 2, 3}}}};
  const auto f = as_map(mrsnake::slicer_segmentation_fields(values, two_values()));
  EXPECT_EQ(f.at("Segmentation_MasterRepresentation"), "Binary labelmap");
  EXPECT_EQ(f.at("Segment0_ID"), "Segment_2");
  EXPECT_EQ(f.at("Segment0_Name"), "left \"cortex\"");
  EXPECT_EQ(f.at("Segment0_LabelValue"), "2");
  EXPECT_EQ(f.at("Segment0_Layer"), "0");
  EXPECT_EQ(f.at("Segment0_Color"), "1 0 0");
  EXPECT_EQ(f.at("Segment0_Extent"), "1 2 0 1 1 1");
  EXPECT_EQ(f.at("Segment1_Color"), "0 0.2 1");
  EXPECT_EQ(f.at("Segment1_Extent"), "3 3 2 2 0 0");
  EXPECT_EQ(f.at("Segment2_Extent"), "0 -1 0 -1 0 -1");  // no voxel: Slicer's empty extent
  EXPECT_EQ(f.count("Segment3_ID"), 0u);
}

TEST(LabelFiles, ColourTableAndLabelDescriptionNameEveryValue) {
  const std::vector<mrsnake::NamedValue> values = {{2, {"left \"cortex\"", {255, 0, 0}}}, {5, {"b", {0, 51, 255}}}};
  const std::string table = mrsnake::slicer_color_table(values);
  EXPECT_NE(table.find("\n0 Background 0 0 0 0\n2 left_\"cortex\" 255 0 0 255\n5 b 0 51 255 255\n"), std::string::npos)
      << table;
  const std::string snap = mrsnake::itksnap_label_description(values);
  EXPECT_NE(snap.find("\"Clear Label\"\n"), std::string::npos) << snap;
  EXPECT_NE(snap.find("    2   255    0    0        1  1  1    \"left 'cortex'\"\n"), std::string::npos) << snap;
  EXPECT_NE(snap.find("    5     0   51  255        1  1  1    \"b\"\n"), std::string::npos) << snap;
}

TEST(LabelFiles, NumberedValuesAreEveryNonZeroValueInOrder) {
  const auto named = mrsnake::numbered_values(two_values());
  ASSERT_EQ(named.size(), 2u);
  EXPECT_EQ(named[0].value, 2);
  EXPECT_EQ(named[0].label.name, mrsnake::default_label_name(2));
  EXPECT_EQ(named[1].value, 5);
  EXPECT_EQ(named[1].label.color, mrsnake::default_label_color(5));
}
