// DICOM series folders as mrsnake's users have them, written by the test itself through ITK:
// a folder of one series reads as its volume; a folder of several is refused with the list of
// its series until --series (segment) or --labels-series / --image-series (build-model) names one.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "mesh/image_io.h"
#include "tests/support/dicom_series_itk.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using mrsnake::test::run_mrsnake;

namespace {

const std::string kImageUid = "1.2.826.0.1.3680043.2.1125.7.1";
const std::string kOtherUid = "1.2.826.0.1.3680043.2.1125.7.2";
const std::string kLabelsUid = "1.2.826.0.1.3680043.2.1125.7.3";

// A volume on an anisotropic, offset grid, so that a reader that loses the geometry shows.
mrsnake::Volume on_oblique_grid(mrsnake::Volume v) {
  v.spacing = {0.8, 0.9, 1.5};
  v.origin = {-12.0, 7.5, 30.0};
  return v;
}

void expect_same_grid(const mrsnake::Volume& a, const mrsnake::Volume& b) {
  EXPECT_EQ(a.size, b.size);
  for (int d = 0; d < 3; ++d) {
    EXPECT_NEAR(a.spacing[d], b.spacing[d], 1e-4) << d;
    EXPECT_NEAR(a.origin[d], b.origin[d], 1e-4) << d;
  }
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(a.direction[i], b.direction[i], 1e-6) << i;
}

}  // namespace

TEST(DicomInput, ASeriesIsChosenByItsUidAndAFolderOfSeveralListsThem) {
  const fs::path dir = mrsnake::test::scratch_dir("dicom");
  const std::string d = dir.string();
  ASSERT_EQ(run_mrsnake("-q synth --shape ellipsoid --size 40 --snr 8 --seed 3 -o " + d + "/case").exit_code, 0);
  mrsnake::Volume image = on_oblique_grid(mrsnake::read_volume(d + "/case/image.nii.gz"));
  for (float& x : image.data) x = std::round(x * 10.f);  // int16 on disk: keep the contrast
  mrsnake::Volume truth = on_oblique_grid(mrsnake::read_volume(d + "/case/truth.nii.gz"));
  mrsnake::write_volume(d + "/truth.nii.gz", truth, mrsnake::VoxelType::uint8);

  // One series: read back voxel for voxel, on its grid.
  fs::create_directories(dir / "one");
  mrsnake::test::write_dicom_series(d + "/one", "img", image, kImageUid, "T2 test");
  const mrsnake::Volume read = mrsnake::read_volume(d + "/one");
  expect_same_grid(read, image);
  EXPECT_EQ(read.data, image.data);

  // Two series in one folder: listed, then chosen.
  fs::create_directories(dir / "two");
  mrsnake::test::write_dicom_series(d + "/two", "img", image, kImageUid, "T2 test");
  mrsnake::Volume other = image;
  for (float& x : other.data) x = 0.5f * x;
  mrsnake::test::write_dicom_series(d + "/two", "other", other, kOtherUid, "scout");
  const auto series = mrsnake::list_dicom_series(d + "/two");
  ASSERT_EQ(series.size(), 2u);
  for (const auto& s : series) EXPECT_EQ(s.files, image.size[2]) << s.id;
  EXPECT_TRUE((series[0].uid == kImageUid && series[1].uid == kOtherUid) ||
              (series[1].uid == kImageUid && series[0].uid == kOtherUid))
      << series[0].uid << " " << series[1].uid;

  ASSERT_EQ(run_mrsnake("-q build-model --labels " + d + "/truth.nii.gz --label 1 --faces 2000 -o " + d + "/m.model")
                .exit_code,
            0);
  const std::string segment = "-q segment --model " + d + "/m.model --image " + d + "/two";
  const auto refused = run_mrsnake(segment + " -o " + d + "/seg-none");
  EXPECT_EQ(refused.exit_code, 3) << refused.output;
  for (const std::string& needle : {std::string("holds 2 DICOM series; choose one by its Series Instance UID"),
                                    kImageUid, kOtherUid, std::string("'T2 test'"), std::string("'scout'")})
    EXPECT_NE(refused.output.find(needle), std::string::npos) << needle << "\n" << refused.output;
  EXPECT_FALSE(fs::exists(dir / "seg-none"));
  EXPECT_EQ(run_mrsnake(segment + " --series 1.2.3.4 -o " + d + "/seg-bad").exit_code, 3);

  const auto chosen =
      run_mrsnake(segment + " --series " + kImageUid + " -o " + d + "/seg --truth " + d + "/truth.nii.gz");
  ASSERT_EQ(chosen.exit_code, 0) << chosen.output;
  const mrsnake::Volume labels = mrsnake::read_volume(d + "/seg/labels.nii.gz");
  expect_same_grid(labels, image);
  EXPECT_GT(std::count(labels.data.begin(), labels.data.end(), 1.0f), 1000);

  // Labels as a series too, chosen with --labels-series; --series on a file is refused.
  mrsnake::test::write_dicom_series(d + "/two", "labels", truth, kLabelsUid, "labels");
  const auto built = run_mrsnake("-q build-model --labels " + d + "/two --labels-series " + kLabelsUid +
                                 " --label 1 --faces 2000 -o " + d + "/dicom.model");
  EXPECT_EQ(built.exit_code, 0) << built.output;
  EXPECT_EQ(run_mrsnake(segment.substr(0, segment.find(" --image")) + " --image " + d + "/truth.nii.gz --series " +
                        kImageUid + " -o " + d + "/seg-file")
                .exit_code,
            3);
  fs::remove_all(dir);
}
