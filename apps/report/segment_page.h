#pragma once
/// \file segment_page.h
/// The report.html page of `mrsnake segment`: three orthogonal slices through the volume with
/// the final contour (and the truth's outline when a truth is given), a 3D render of the
/// surface, a convergence plot per level, the scores and the timings.
///
/// The page takes plain data (no snake types), so the report library stays below the
/// segmentation in the layers; cmd_segment fills it from SegmentResult and segment_report.
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/trimesh.h"
#include "mesh/volume.h"

namespace mrsnake::reports {

/// The convergence history of one level of the snake: one entry per iteration.
struct SnakeConvergence {
  int level = 0;
  std::vector<double> energy;           ///< external + internal
  std::vector<double> external_energy;  ///< mean matched cost
  std::vector<double> internal_energy;
  std::vector<double> mean_abs_offset_mm;  ///< mean |matched offset|, mm
  bool deformed = true;                    ///< false: finer than the image, only synthesized (no iterations)
};

/// One structure of a model of several: its final surface, name, label value and colour.
struct PageStructure {
  const TriMesh* surface = nullptr;
  std::string name;
  int value = 0;
  std::array<int, 3> color{255, 64, 64};
};

struct SegmentPageInput {
  std::string title = "mrsnake segment";
  const Volume* image = nullptr;     ///< the segmented volume (required)
  const TriMesh* surface = nullptr;  ///< the final surface (required; the first structure's)
  /// With more than one: every structure's contour in its colour on the slices, one render of
  /// all the surfaces, and a table of their volumes and verdicts (report["structures"]).
  std::vector<PageStructure> structures;
  const Volume* truth = nullptr;              ///< optional truth labels on the image's grid
  float truth_label = 1;                      ///< the object's value in *truth
  std::vector<SnakeConvergence> convergence;  ///< per level; empty: the plots say so
  /// With several structures: the name of the one whose convergence is shown.
  std::string convergence_of;
  /// segment_report's JSON (levels, scores, stage_seconds, initial_pose, ...), shown as tables.
  nlohmann::json report;
  /// Renders are attempted only when reports::display_available(); set false to never try.
  bool renders = true;
};

/// The page as HTML. Every picture that cannot be made (no display, a render error) becomes
/// a note in the page instead; this never throws for a picture.
/// \pre input.image and input.surface are set.
/// \throw std::invalid_argument if they are not.
std::string segment_report_html(const SegmentPageInput& input);

/// PNG bytes of the page's three orthogonal slices side by side, each at most `size` pixels:
/// a thumbnail of the result for study pages and file browsers.
/// \pre input.image and input.surface are set; size > 0.
/// \throw std::invalid_argument if they are not set; Error if the slices cannot be drawn.
std::vector<std::uint8_t> slices_png(const SegmentPageInput& input, int size = 200);

/// Writes segment_report_html atomically to `path`.
/// \throw OutputError if the file cannot be written.
void write_segment_report(const std::string& path, const SegmentPageInput& input);

}  // namespace mrsnake::reports
