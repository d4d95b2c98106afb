#include "apps/report/remesh_page.h"

#include <algorithm>
#include <memory>
#include <cmath>
#include <cstdio>
#include <exception>

#include "apps/report/html.h"
#include "apps/report/plots.h"
#include "apps/report/render.h"
#include "mesh/atomic_file.h"
#include "mesh/distance.h"
#include "mesh/json_text.h"
#include "mesh/quality.h"

namespace mrsnake::reports {
namespace {

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

/// A number of a json object at a key, or "–" when it is absent.
std::string cell(const nlohmann::json& j, const char* key, int digits) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return "–";
  return fixed(j[key].get<double>(), digits);
}

/// A setting's value as text: strings as they are, numbers with 4 significant digits.
std::string setting(const nlohmann::json& v) {
  if (v.is_string()) return v.get<std::string>();
  if (v.is_number_float()) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.4g", v.get<double>());
    return buf;
  }
  return json_text(v);
}

/// Points measured per mesh for the page's distances: a 179k-face marching-cubes input has
/// 90k vertices, measured against every level; a random subset of this many keeps the RMS
/// unbiased and costs a fraction of the time (the page says so).
constexpr long long kMaxDistanceSamples = 30000;

/// Quality and distance of one level: from its stats when remesh computed them, else
/// computed here (distance only when the input is known).
/// `given_locator` (built on `input`) is used when not null; else `locator` is built on
/// `input` at the first use and reused for the other levels.
std::pair<nlohmann::json, nlohmann::json> level_figures(const RemeshResult& result, int j, const TriMesh* input,
                                                        const SurfaceLocator* given_locator,
                                                        std::unique_ptr<SurfaceLocator>& locator, int samples_per_face,
                                                        bool* computed) {
  const nlohmann::json& s = result.levels[j].stats;
  nlohmann::json quality = s.contains("quality") ? s["quality"] : nlohmann::json(mesh_quality(result.mesh(j)));
  nlohmann::json distance = s.contains("distance") ? s["distance"] : nlohmann::json();
  if (distance.is_null() && input) {
    DistanceOptions o;
    o.samples_per_face = samples_per_face;
    o.max_samples_per_mesh = kMaxDistanceSamples;
    if (!given_locator && !locator) locator = std::make_unique<SurfaceLocator>(*input);
    distance = surface_distance(result.mesh(j), *input, given_locator ? *given_locator : *locator, o);
    *computed = true;
  }
  return {quality, distance};
}

std::vector<double> all_angles_deg(const TriMesh& mesh) {
  std::vector<double> angles;
  angles.reserve(3 * mesh.F.rows());
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d p = mesh.V.row(mesh.F(f, k));
      const Eigen::Vector3d a = Eigen::Vector3d(mesh.V.row(mesh.F(f, (k + 1) % 3))) - p;
      const Eigen::Vector3d b = Eigen::Vector3d(mesh.V.row(mesh.F(f, (k + 2) % 3))) - p;
      angles.push_back(std::atan2(a.cross(b).norm(), a.dot(b)) * 180.0 / M_PI);
    }
  return angles;
}

/// Lengths of the distinct edges, divided by their mean (the normalization of Fig. 2's
/// edge length variance).
std::vector<double> normalized_edge_lengths(const TriMesh& mesh) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * mesh.F.rows());
  for (Eigen::Index f = 0; f < mesh.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = mesh.F(f, k), b = mesh.F(f, (k + 1) % 3);
      edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::vector<double> lengths;
  lengths.reserve(edges.size());
  double sum = 0;
  for (const auto& [a, b] : edges) {
    lengths.push_back((mesh.V.row(a) - mesh.V.row(b)).norm());
    sum += lengths.back();
  }
  const double mean = lengths.empty() ? 1.0 : sum / static_cast<double>(lengths.size());
  for (double& l : lengths) l /= mean > 0 ? mean : 1.0;
  return lengths;
}

/// Runs a picture maker; its failure becomes a note in the page.
template <class Make>
void picture(HtmlPage& page, const std::string& what, Make&& make) {
  try {
    make();
  } catch (const std::exception& e) {
    page.note(what + " could not be drawn: " + e.what());
  }
}

constexpr int kWireframeFaceLimit = 40000;  // beyond this the edges hide the surface

}  // namespace

std::vector<double> face_stretch(const RemeshResult& result, int level) {
  const auto& F = result.connectivity.faces[level];
  const auto& X = result.levels[level].positions;
  const auto& U = result.levels[level].domain_positions;
  std::vector<double> stretch(F.rows(), 0.0);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const auto area = [&](const RowMatrixX3d& P) {
      const Eigen::Vector3d a = P.row(F(f, 0)), b = P.row(F(f, 1)), c = P.row(F(f, 2));
      return 0.5 * (b - a).cross(c - a).norm();
    };
    const double domain_area = area(U);
    stretch[f] = domain_area > 0 ? area(X) / domain_area : 0.0;
  }
  return stretch;
}

std::string remesh_report_html(const RemeshResult& result, const RemeshPageOptions& options) {
  HtmlPage page(options.title);
  const int L = static_cast<int>(result.levels.size()) - 1;
  const RemeshResult* unrelaxed = options.unrelaxed;
  if (unrelaxed && unrelaxed->levels.size() != result.levels.size()) unrelaxed = nullptr;

  // First what makes the finest level doubtful, which its figures below do not show at a glance.
  for (const std::string& doubt : finest_level_doubts(result).value_or(std::vector<std::string>{}))
    page.note("Suspect: " + doubt + ".");

  // Settings.
  const nlohmann::json& r = options.report;
  std::vector<std::vector<std::string>> settings;
  settings.push_back({"domain", result.domain});
  settings.push_back({"levels L", std::to_string(L)});
  settings.push_back({"faces (finest)", std::to_string(result.connectivity.faces.back().rows())});
  settings.push_back({"base vertices n0", std::to_string(result.levels.front().positions.rows())});
  for (const char* key : {"input", "relax", "density_exponent", "curvature_weight", "lloyd_iterations",
                          "shape_iterations", "guarded_shape_iterations"})
    if (r.is_object() && r.contains(key)) settings.push_back({key, setting(r[key])});
  if (result.parameterization.is_object())
    for (const auto& [key, value] : result.parameterization.items())
      if (!value.is_structured()) settings.push_back({"parameterization " + key, setting(value)});
  if (options.input) settings.push_back({"input faces", std::to_string(options.input->num_faces())});
  page.heading("Settings");
  page.table({"setting", "value"}, settings);

  // Quality per level (Fig. 2 of the paper, plus regularity and the Frey–Borouchaki Q).
  page.heading("Quality per level");
  page.paragraph(
      "The columns of the seed paper's Fig. 2: geometric error (RMS distance to the input, % of its bounding-box "
      "diagonal), variance of the angles (deg²), smallest angle, variance of the edge lengths normalized by their "
      "mean, "
      "and the shape factor Q (Frey–Borouchaki, 1 = equilateral; min and mean); plus the share of interior vertices "
      "of valence 6 and the Hausdorff distance." +
      std::string(unrelaxed ? " 'unrelaxed' is the same input and base split 1:4 without any relaxation "
                              "(--compare-unrelaxed)."
                            : ""));
  std::vector<std::vector<std::string>> rows;
  bool distance_missing = false, distance_computed = false;
  int samples = options.distance_samples_per_face;
  if (samples <= 0)
    samples = options.input
                  ? std::clamp(static_cast<int>(100000 / std::max<Eigen::Index>(1, options.input->num_faces())), 0, 10)
                  : 10;
  std::unique_ptr<SurfaceLocator> input_locator;
  const auto add_rows = [&](const RemeshResult& res, const std::string& variant) {
    for (int j = 0; j <= L; ++j) {
      const auto [q, d] =
          level_figures(res, j, options.input, options.input_locator, input_locator, samples, &distance_computed);
      if (d.is_null()) distance_missing = true;
      rows.push_back({std::to_string(j), variant, std::to_string(res.levels[j].positions.rows()),
                      std::to_string(res.connectivity.faces[j].rows()), cell(d, "rms_pct", 3),
                      cell(d, "hausdorff_pct", 3), cell(q, "angle_variance_deg2", 1), cell(q, "min_angle_deg", 2),
                      cell(q, "edge_length_variance", 4), cell(q, "q_min", 3), cell(q, "q_mean", 3),
                      cell(q, "pct_valence6_interior", 2), std::to_string(res.levels[j].flipped_triangles)});
    }
  };
  add_rows(result, unrelaxed ? "relaxed" : "");
  if (unrelaxed) add_rows(*unrelaxed, "unrelaxed");
  if (unrelaxed)  // side by side: sort by level, relaxed first
    std::stable_sort(rows.begin(), rows.end(),
                     [](const auto& a, const auto& b) { return std::stoi(a[0]) < std::stoi(b[0]); });
  std::vector<std::string> header = {"level",
                                     "variant",
                                     "vertices",
                                     "faces",
                                     "RMS error %",
                                     "Hausdorff %",
                                     "angle variance (deg²)",
                                     "min angle (°)",
                                     "edge length variance",
                                     "Q min",
                                     "Q mean",
                                     "valence 6 %",
                                     "flipped in D"};
  if (!unrelaxed) {  // one variant: no column for it
    header.erase(header.begin() + 1);
    for (auto& row : rows) row.erase(row.begin() + 1);
  }
  page.table(header, rows);
  if (distance_computed)
    page.paragraph("Distances of this page: every vertex" +
                   (samples > 0 ? " plus " + std::to_string(samples) + " random point(s) per face" : std::string()) +
                   " of each mesh (a uniform random subset of " + std::to_string(kMaxDistanceSamples) +
                   " of them for a mesh with more: the RMS is an unbiased estimate, the Hausdorff distance the largest "
                   "over the subset), measured against the other (model.json's remesh_quality has none: build-model's "
                   "\"report\": {\"level_stats\": true} in --config gives the remeshing's own figures).");
  if (distance_missing) page.note("The geometric error needs the input surface; it was not given to this page.");

  // Renders of every level.
  page.heading("Levels");
  std::string why;
  const bool can_render = options.renders && display_available(&why);
  if (!options.renders) why = "3D renders were turned off";
  if (!can_render) {
    page.note("No 3D renders of the levels and the domain: " + why + ".");
  } else {
    page.begin_figures();
    for (int j = 0; j <= L; ++j)
      picture(page, "The render of level " + std::to_string(j), [&] {
        RenderOptions ro;
        ro.width = 420;
        ro.height = 340;
        ro.wireframe = result.connectivity.faces[j].rows() <= kWireframeFaceLimit;
        page.png(render_mesh_png(result.mesh(j), ro),
                 "level " + std::to_string(j) + ": " + std::to_string(result.connectivity.faces[j].rows()) + " faces" +
                     (ro.wireframe ? "" : " (too many for a wireframe)"));
      });
    if (unrelaxed)
      picture(page, "The render of the unrelaxed finest level", [&] {
        RenderOptions ro;
        ro.width = 420;
        ro.height = 340;
        ro.wireframe = unrelaxed->connectivity.faces[L].rows() <= kWireframeFaceLimit;
        page.png(render_mesh_png(unrelaxed->mesh(L), ro), "level " + std::to_string(L) + " without relaxation");
      });
    page.end_figures();
  }

  // The parametric domain coloured by the stretch.
  page.heading("Parametric domain");
  page.paragraph(
      "The finest level's mesh in the domain D (" + result.domain +
      "), each face coloured by its stretch A_3D / A_D (log10) between the finest level and its domain mesh: "
      "red regions of D are sampled densely. The Lloyd density is (stretch·w)^density_exponent, w the "
      "curvature sizing.");
  if (can_render) {
    picture(page, "The domain picture", [&] {
      const std::vector<double> stretch = face_stretch(result, L);
      // Colours over the 1st to 99th percentile: a few faces at a pole would otherwise
      // squeeze everything else into one colour.
      std::vector<double> sorted = stretch;
      std::sort(sorted.begin(), sorted.end());
      const double p1 = sorted[sorted.size() / 100], p99 = sorted[sorted.size() - 1 - sorted.size() / 100];
      RenderOptions ro;
      ro.width = 560;
      ro.height = 460;
      ro.face_scalars = stretch;
      for (double& v : ro.face_scalars) v = std::clamp(v, p1, p99);
      ro.log_scale = true;
      ro.scalar_title = "stretch";
      ro.wireframe = result.connectivity.faces[L].rows() <= kWireframeFaceLimit / 2;
      if (result.domain == "disk") ro.azimuth = ro.elevation = 0;  // the z = 1 plane, seen from above
      const TriMesh domain{result.levels[L].domain_positions, result.connectivity.faces[L]};
      const auto [lo, hi] = std::minmax_element(stretch.begin(), stretch.end());
      page.begin_figures();
      page.png(render_mesh_png(domain, ro), "domain of level " + std::to_string(L) + ", stretch from " + fixed(*lo, 3) +
                                                " to " + fixed(*hi, 3) + " (colours: 1st to 99th percentile)");
      if (result.domain == "sphere") {
        ro.azimuth += 180;  // the far side of the sphere
        page.png(render_mesh_png(domain, ro), "the far side");
      }
      page.end_figures();
    });
  } else {
    page.note("No picture of the domain: " + why + ".");
  }

  // Histograms of the finest level.
  page.heading("Angles and edge lengths (level " + std::to_string(L) + ")");
  const auto histograms = [&](const RemeshResult& res, const std::string& variant) {
    page.begin_figures();
    const TriMesh mesh = res.mesh(L);
    picture(page, "The angle histogram", [&] {
      page.svg(svg_histogram(all_angles_deg(mesh), 60, 0, 180, "Angles" + variant, "angle (degrees)"),
               "all triangle angles" + variant + " (60° = equilateral)");
    });
    picture(page, "The edge length histogram", [&] {
      page.svg(
          svg_histogram(normalized_edge_lengths(mesh), 50, 0, 2.5, "Edge lengths" + variant, "length / mean length"),
          "edge lengths" + variant + ", divided by their mean");
    });
    page.end_figures();
  };
  histograms(result, unrelaxed ? " (relaxed)" : "");
  if (unrelaxed) histograms(*unrelaxed, " (unrelaxed)");

  // Timings.
  std::vector<std::vector<std::string>> times;
  if (!options.timings.empty()) {
    for (const auto& [stage, seconds] : options.timings) times.push_back({stage, fixed(seconds, 3)});
  } else {
    times.push_back({"parameterization", cell(result.parameterization, "seconds", 3)});
    for (int j = 0; j <= L; ++j) times.push_back({"level " + std::to_string(j), fixed(result.levels[j].seconds, 3)});
  }
  page.heading("Timings");
  page.table({"stage", "seconds"}, times);
  return page.str();
}

void write_remesh_report(const std::string& path, const RemeshResult& result, const RemeshPageOptions& options) {
  write_text_file_atomically(path, remesh_report_html(result, options));
}

}  // namespace mrsnake::reports
