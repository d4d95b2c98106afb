#pragma once
/// \file remesh_page.h
/// The report.html page of `mrsnake remesh` and `mrsnake build-model`: the quality table per
/// level (the seed paper's Fig. 2 columns), renders of every level, the parametric domain
/// coloured by the stretch, and histograms of angles and edge lengths.
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/distance.h"
#include "mesh/trimesh.h"
#include "remesh/remesh.h"

namespace mrsnake::reports {

/// What the remesh page shows besides the result itself.
struct RemeshPageOptions {
  std::string title = "mrsnake remesh";
  /// The input surface: quality and distance of levels whose stats lack them are computed
  /// against it (build-model computes no stats by default). Null: such cells stay empty.
  const TriMesh* input = nullptr;
  /// A closest-point locator already built on `input` (e.g. while the parameterization ran),
  /// or null: the page builds one when it needs it.
  const SurfaceLocator* input_locator = nullptr;
  /// Random samples per face of both meshes for those distances; 0 = automatic: 10 (as
  /// remesh's own stats), fewer for a large input so that it gets about 100,000 samples, and
  /// none beyond the vertices for an input of more than 100,000 faces (whose vertices are
  /// dense enough: the distances of every level to a 440k-face liver took 27 s with 10).
  int distance_samples_per_face = 0;
  /// The same input remeshed with RelaxMode::none (--compare-unrelaxed), or null.
  const RemeshResult* unrelaxed = nullptr;
  /// The report.json of the run (remesh_report plus extras), shown as the settings table.
  nlohmann::json report;
  /// Stage timings in seconds, in order (build-model), shown as a table when not empty.
  std::vector<std::pair<std::string, double>> timings;
  /// Renders are attempted only when reports::display_available(); set false to never try.
  bool renders = true;
};

/// The page as HTML text. Every picture that cannot be made (no display, a render error)
/// becomes a note in the page instead; this never throws for a picture.
/// \pre result has at least one level.
std::string remesh_report_html(const RemeshResult& result, const RemeshPageOptions& options);

/// Writes remesh_report_html atomically to `path`.
/// \throw OutputError if the file cannot be written.
void write_remesh_report(const std::string& path, const RemeshResult& result, const RemeshPageOptions& options);

/// Stretch A_3D / A_D of every face of a level (the sampling density the Lloyd step
/// follows, to the power of its exponent); 0 where the domain triangle has no area.
std::vector<double> face_stretch(const RemeshResult& result, int level);

}  // namespace mrsnake::reports
