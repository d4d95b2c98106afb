#pragma once
/// \file segment_case.h
/// One image segmented with a model of one or more structures, as `segment` and
/// `segment-batch` run it: the image prepared and registered once, every structure deformed,
/// one label map with no voxel claimed twice, a verdict per structure, and the output folder
/// written atomically.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "apps/case_fingerprint.h"
#include "mesh/image_io.h"
#include "mesh/progress.h"
#include "model/label_names.h"
#include "snake/segment.h"

namespace mrsnake::cli {

/// The model as the segmentation uses it.
struct SegmentModel {
  std::vector<SnakeModel> structures;
  std::vector<int> values;        ///< the reference's label value of each structure
  std::vector<LabelName> labels;  ///< their names and colours
  std::size_t registering = 0;    ///< the structure whose registration every structure shares: the largest
  double load_seconds = 0;
  std::string fingerprint;  ///< model_fingerprint of its folder
};

/// \throw InputError as load_model_set does.
SegmentModel load_segment_model(const std::string& path);

/// The voxel type of the model's label map: uint8, or int16 for values above 255.
VoxelType label_voxel_type(const SegmentModel& model);

/// One image to segment, and where.
struct SegmentCase {
  std::string image, truth, output;
  std::string series;  ///< the DICOM series of a folder `image` that holds several (read_volume)
  /// case_fingerprint of the image, when the caller has it already (segment-batch --resume).
  std::optional<CaseFingerprint> fingerprint;
  /// The structure's value in the truth, for a model of one structure; < 0: its own value,
  /// or 1 (as synth writes a truth) when the truth does not hold it. A model of several is
  /// scored on each structure's own value.
  int truth_label = -1;
};

struct SegmentCaseOutcome {
  nlohmann::json report;
  std::vector<SegmentResult> results;  ///< per structure
  Volume labels;                       ///< the label map written as labels.nii.gz
};

/// What a segmentation of `image` with this model and these options records in report.json.
/// \throw InputError if the image cannot be read.
CaseFingerprint case_fingerprint(const std::string& image, const std::string& series, const SegmentModel& model,
                                 const SegmentOptions& options);

/// The report.json of an earlier result in `output` that is complete (every file segment
/// writes is there, but for the slices.png thumbnail) and was made from `expected`; null
/// otherwise, and when `expected` is not comparable.
nlohmann::json reusable_result(const std::string& output, const SegmentModel& model, const CaseFingerprint& expected);

/// Segments the case into its output folder (replacing only an earlier result of segment):
/// labels.nii.gz, surfaces/<value>.vtp, report.json, report.html, slices.png, and for a model of one
/// structure also surface.vtp and levels/level_j.vtp.
/// \throw the errors of reading the inputs, of segment() and of the writes; OutputError if the
///        output path holds other data.
SegmentCaseOutcome segment_case(const SegmentCase& c, const SegmentModel& model, const std::string& model_path,
                                const SegmentOptions& options, double model_load_seconds, const ProgressFn& progress);

}  // namespace mrsnake::cli
