#include "apps/report/segment_page.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <exception>
#include <stdexcept>

#include "apps/report/html.h"
#include "apps/report/plots.h"
#include "apps/report/render.h"
#include "apps/report/slices.h"
#include "mesh/atomic_file.h"
#include "mesh/json_text.h"
#include "mesh/marching_cubes.h"
#include "mesh/merge.h"

namespace mrsnake::reports {
namespace {

std::string text(const nlohmann::json& v, int digits = 4) {
  if (v.is_null()) return "–";
  if (v.is_boolean()) return v.get<bool>() ? "yes" : "no";
  if (v.is_number_integer()) return std::to_string(v.get<long long>());
  if (v.is_number()) {
    char buf[64];
    const double x = v.get<double>();
    if (std::abs(x) >= 1e4 && std::abs(x) < 1e12)
      std::snprintf(buf, sizeof buf, "%.0f", x);  // volumes in mm³: no exponent
    else
      std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    return buf;
  }
  if (v.is_string()) return v.get<std::string>();
  if (v.is_array()) {
    std::string out;
    for (const auto& e : v) out += (out.empty() ? "" : ", ") + text(e, digits);
    return out;
  }
  return json_text(v);
}

template <class Make>
void picture(HtmlPage& page, const std::string& what, Make&& make) {
  try {
    make();
  } catch (const std::exception& e) {
    page.note(what + " could not be drawn: " + e.what());
  }
}

std::vector<double> iterations(std::size_t n) {
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = static_cast<double>(i);
  return x;
}

// Every structure's surface as one mesh, each face carrying its structure's label value.
TriMesh merged_surfaces(const std::vector<PageStructure>& structures, std::vector<double>& face_values) {
  std::vector<const TriMesh*> surfaces;
  face_values.clear();
  for (const PageStructure& s : structures) {
    surfaces.push_back(s.surface);
    face_values.insert(face_values.end(), s.surface->num_faces(), s.value);
  }
  return merged_meshes(surfaces);
}

const char* const kAxisNames[] = {"sagittal (x)", "coronal (y)", "axial (z)"};

// What the slices show: every structure's contour in its colour, or the one surface in red
// with the truth's outline in green.
struct SliceOverlay {
  bool several = false;
  TriMesh all;  ///< with several structures: all their surfaces as one mesh
  std::vector<double> face_values;
  const TriMesh* surface = nullptr;
  std::vector<MeshContour> meshes;
  std::vector<LabelContour> labels;
  const TriMesh& centred() const { return several ? all : *surface; }
};

SliceOverlay slice_overlay(const SegmentPageInput& in) {
  SliceOverlay o;
  o.several = in.structures.size() > 1;
  o.surface = in.surface;
  if (!o.several) {
    if (in.truth) o.labels.push_back({in.truth, in.truth_label, {64, 220, 64}, "truth"});
    o.meshes.push_back({in.surface, {255, 64, 64}, "segmentation"});
    return o;
  }
  o.all = merged_surfaces(in.structures, o.face_values);
  for (const PageStructure& s : in.structures)
    o.meshes.push_back({s.surface,
                        {static_cast<std::uint8_t>(s.color[0]), static_cast<std::uint8_t>(s.color[1]),
                         static_cast<std::uint8_t>(s.color[2])},
                        s.name});
  return o;
}

// The table of a model of several structures: volume, volume against the model, verdict.
void structures_table(HtmlPage& page, const nlohmann::json& r) {
  if (!r.is_object() || !r.contains("structures") || r["structures"].size() < 2) return;
  std::vector<std::vector<std::string>> rows;
  for (const nlohmann::json& s : r["structures"]) {
    const auto& c = s["color"];
    rows.push_back({text(s["value"]), s["name"].get<std::string>(),
                    "rgb(" + text(c[0]) + ", " + text(c[1]) + ", " + text(c[2]) + ")", text(s["volume_mm3"]),
                    text(s["volume_ratio_to_model"]),
                    s.contains("scores") && s["scores"].contains("dice") ? text(s["scores"]["dice"]) : "–",
                    s["suspect"].get<bool>() ? "suspect" : "ok", s["reason"].get<std::string>()});
  }
  page.heading("Structures");
  page.table({"value", "name", "colour", "volume (mm³)", "volume / model", "Dice", "verdict", "reason"}, rows);
}

}  // namespace

std::string segment_report_html(const SegmentPageInput& in) {
  if (!in.image || !in.surface)
    throw std::invalid_argument("segment_report_html: the image and the surface are required");
  HtmlPage page(in.title);
  const nlohmann::json& r = in.report;

  // Summary and scores.
  std::vector<std::vector<std::string>> summary;
  for (const char* key : {"image", "model", "truth", "force", "init", "vertices", "faces", "converged", "final_energy",
                          "self_intersections", "compute_seconds"})
    if (r.is_object() && r.contains(key)) summary.push_back({key, text(r[key])});
  if (r.is_object() && r.contains("initial_pose") && r["initial_pose"].is_object())
    for (const auto& [key, value] : r["initial_pose"].items()) summary.push_back({"initial pose " + key, text(value)});
  page.heading("Summary");
  page.table({"item", "value"}, summary);
  if (r.is_object() && r.contains("scores") && r["scores"].is_object()) {
    std::vector<std::vector<std::string>> scores;
    for (const auto& [key, value] : r["scores"].items()) scores.push_back({key, text(value)});
    page.heading("Scores against the truth");
    page.table({"score", "value"}, scores);
  }
  structures_table(page, r);

  // Slices.
  page.heading("Slices");
  const SliceOverlay overlay = slice_overlay(in);
  if (overlay.several) {
    page.paragraph(
        "Three orthogonal slices through the centre of all the structures, each structure's contour in "
        "its colour (the table above).");
  } else {
    page.paragraph(
        std::string("Three orthogonal slices through the centre of the final surface: the final contour in red") +
        (in.truth ? ", the truth's outline in green (hidden under the red where the two agree)."
                  : ". (No --truth was given.)"));
  }
  page.begin_figures();
  std::array<double, 3> centre{};
  picture(page, "The slice centre", [&] { centre = mesh_centre_index(*in.image, overlay.centred()); });
  for (int axis = 0; axis < 3; ++axis)
    picture(page, std::string("The ") + kAxisNames[axis] + " slice", [&] {
      const Canvas c = slice_with_contours(*in.image, axis, centre[axis], overlay.meshes, overlay.labels, 360);
      char caption[96];
      std::snprintf(caption, sizeof caption, "%s slice at voxel %.0f", kAxisNames[axis], std::round(centre[axis]));
      page.png(c.png(), caption);
    });
  page.end_figures();

  // 3D render.
  page.heading("Surface");
  const bool several = overlay.several;
  const TriMesh& all = overlay.all;
  const std::vector<double>& face_values = overlay.face_values;
  std::string why;
  const bool can_render = in.renders && display_available(&why);
  if (!in.renders) why = "3D renders were turned off";
  if (!can_render) {
    page.note("No 3D render of the surface: " + why + ".");
  } else if (several) {
    picture(page, "The 3D render", [&] {
      RenderOptions ro;
      ro.width = 560;
      ro.height = 460;
      ro.wireframe = false;
      ro.face_scalars = face_values;
      ro.scalar_title = "label value";
      page.begin_figures();
      page.png(render_mesh_png(all, ro), "every structure's surface, coloured by its label value");
      ro.azimuth += 180;
      page.png(render_mesh_png(all, ro), "the other side");
      page.end_figures();
    });
  } else {
    picture(page, "The 3D render", [&] {
      TriMesh truth_surface;
      RenderOptions ro;
      ro.width = 560;
      ro.height = 460;
      ro.wireframe = in.surface->num_faces() <= 40000;
      if (in.truth) {
        truth_surface = extract_label_surface(*in.truth, static_cast<int>(std::lround(in.truth_label))).mesh;
        ro.overlay = &truth_surface;
      }
      page.begin_figures();
      page.png(render_mesh_png(*in.surface, ro),
               std::string("final surface") + (in.truth ? " with the truth surface in translucent green" : ""));
      ro.azimuth += 180;
      page.png(render_mesh_png(*in.surface, ro), "the other side");
      page.end_figures();
    });
  }

  // Convergence.
  page.heading("Convergence");
  if (in.convergence.empty()) {
    page.note("No convergence history was recorded.");
  } else {
    page.paragraph(
        "Energy (mean matched cost plus the internal term) and the mean |matched offset| along the normals "
        "at each iteration of each level" +
        (in.convergence_of.empty() ? std::string(".")
                                   : " of " + in.convergence_of + "; report.json holds every structure's levels."));
    page.begin_figures();
    for (const SnakeConvergence& c : in.convergence) {
      if (!c.deformed) {
        page.note("Level " + std::to_string(c.level) +
                  " was not deformed: its edges are finer than the image allows (min_edge_voxels) and its profiles "
                  "are not centred on the image's edges, so it is the wavelet synthesis of the level before.");
        continue;
      }
      picture(page, "The convergence plot of level " + std::to_string(c.level), [&] {
        std::vector<Series> series;
        if (!c.energy.empty()) series.push_back({"energy", iterations(c.energy.size()), c.energy});
        if (!c.external_energy.empty())
          series.push_back({"external", iterations(c.external_energy.size()), c.external_energy});
        if (!c.internal_energy.empty())
          series.push_back({"internal", iterations(c.internal_energy.size()), c.internal_energy});
        if (series.empty()) throw std::runtime_error("no iterations were recorded");
        page.svg(svg_line_plot(series, "Level " + std::to_string(c.level) + " energy", "iteration", "energy"),
                 "level " + std::to_string(c.level) + ": " + std::to_string(c.energy.size()) + " iterations");
      });
    }
    picture(page, "The offset plot", [&] {
      std::vector<Series> series;
      for (const SnakeConvergence& c : in.convergence)
        if (!c.mean_abs_offset_mm.empty())
          series.push_back(
              {"level " + std::to_string(c.level), iterations(c.mean_abs_offset_mm.size()), c.mean_abs_offset_mm});
      if (series.empty()) throw std::runtime_error("no offsets were recorded");
      page.svg(svg_line_plot(series, "Mean |matched offset|", "iteration", "mm"), "mean |matched offset| per level");
    });
    page.end_figures();
  }

  // Levels and timings.
  if (r.is_object() && r.contains("levels") && r["levels"].is_array() && !r["levels"].empty()) {
    const std::vector<std::pair<const char*, const char*>> columns = {{"level", "level"},
                                                                      {"vertices", "vertices"},
                                                                      {"pyramid_level", "pyramid level"},
                                                                      {"voxel_mm", "voxel (mm)"},
                                                                      {"search_range_mm", "search range (mm)"},
                                                                      {"iterations", "iterations"},
                                                                      {"converged", "converged"},
                                                                      {"energy", "energy"},
                                                                      {"mean_abs_offset_mm", "mean |offset| (mm)"},
                                                                      {"rejected_steps", "rejected steps"},
                                                                      {"rolled_back_vertices", "rolled back"},
                                                                      {"deformed", "deformed"},
                                                                      {"offset_smoothing", "offset averaging passes"},
                                                                      {"flipped_faces", "flipped faces"},
                                                                      {"synthesis_seconds", "synthesis (s)"},
                                                                      {"seconds", "seconds"}};
    std::vector<std::string> header;
    for (const auto& c : columns) header.push_back(c.second);
    std::vector<std::vector<std::string>> rows;
    for (const auto& level : r["levels"]) {
      std::vector<std::string> row;
      for (const auto& c : columns) row.push_back(level.contains(c.first) ? text(level[c.first]) : "–");
      rows.push_back(row);
    }
    page.heading("Levels");
    page.table(header, rows);
  }
  page.heading("Timings");
  if (r.is_object() && r.contains("stage_seconds") && r["stage_seconds"].is_object() && !r["stage_seconds"].empty()) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& [stage, seconds] : r["stage_seconds"].items()) rows.push_back({stage, text(seconds)});
    page.table({"stage", "seconds"}, rows);
  } else {
    page.note("No timings were recorded.");
  }
  return page.str();
}

std::vector<std::uint8_t> slices_png(const SegmentPageInput& in, int size) {
  if (!in.image || !in.surface) throw std::invalid_argument("slices_png: the image and the surface are required");
  const SliceOverlay overlay = slice_overlay(in);
  const std::array<double, 3> centre = mesh_centre_index(*in.image, overlay.centred());
  std::vector<Canvas> slices;
  int width = 0, height = 0;
  for (int axis = 0; axis < 3; ++axis) {
    slices.push_back(slice_with_contours(*in.image, axis, centre[axis], overlay.meshes, overlay.labels, size));
    width += slices.back().width();
    height = std::max(height, slices.back().height());
  }
  Canvas strip(width, height);
  int x0 = 0;
  for (const Canvas& c : slices) {
    for (int y = 0; y < c.height(); ++y)
      for (int x = 0; x < c.width(); ++x) strip.set(x0 + x, y, c.get(x, y));
    x0 += c.width();
  }
  return strip.png();
}

void write_segment_report(const std::string& path, const SegmentPageInput& input) {
  write_text_file_atomically(path, segment_report_html(input));
}

}  // namespace mrsnake::reports
