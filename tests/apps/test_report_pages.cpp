// The HTML pages of remesh and build-model: every section, the expected pictures, and the
// note in place of the 3D renders when no display is available.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "apps/report/remesh_page.h"
#include "apps/report/render.h"
#include "apps/report/segment_page.h"
#include "mesh/mesh_io.h"
#include "mesh/primitives.h"
#include "remesh/remesh.h"
#include "tests/test_support.h"

using namespace mrsnake;
namespace fs = std::filesystem;

namespace {

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + what.size())) ++n;
  return n;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs the mrsnake binary with DISPLAY unset, as on a machine without X or Xvfb.
test::CommandResult run_without_display(const std::string& args) {
  test::CommandResult r;
  const char* bin = std::getenv("MRSNAKE_BIN");
  if (!bin) return r;
  FILE* pipe = popen(("env -u DISPLAY " + std::string(bin) + " " + args + " 2>&1").c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  while (fgets(buf, sizeof buf, pipe)) r.output += buf;
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

struct Remeshed {
  TriMesh input = icosphere(3, 10.0);
  RemeshResult relaxed, unrelaxed;
  Remeshed() {
    RemeshOptions o;
    o.levels = 2;
    o.base_vertices = 24;
    relaxed = remesh(input, o);
    o.relax = RelaxMode::none;
    unrelaxed = remesh(input, o);
  }
};

const Remeshed& remeshed() {
  static const Remeshed r;
  return r;
}

const char* kSections[] = {"<h2>Settings</h2>",
                           "<h2>Quality per level</h2>",
                           "<h2>Levels</h2>",
                           "<h2>Parametric domain</h2>",
                           "<h2>Angles and edge lengths (level 2)</h2>",
                           "<h2>Timings</h2>"};

}  // namespace

TEST(RemeshPage, EverySectionAndPictureWithTheComparison) {
  const Remeshed& r = remeshed();
  reports::RemeshPageOptions options;
  options.input = &r.input;
  options.unrelaxed = &r.unrelaxed;
  const std::string html = reports::remesh_report_html(r.relaxed, options);
  for (const char* section : kSections) EXPECT_EQ(count(html, section), 1) << section;
  // One table row per level and variant, each with a measured RMS error (not the empty mark).
  EXPECT_EQ(count(html, "<td>relaxed</td>"), 3);
  EXPECT_EQ(count(html, "<td>unrelaxed</td>"), 3);
  EXPECT_EQ(count(html, "–</td>"), 0) << "a quality cell is empty";
  // Histograms of angles and edge lengths, relaxed and unrelaxed: inline SVG.
  EXPECT_EQ(count(html, "<svg"), 4);
  if (reports::display_available()) {
    // Levels 0..2, the unrelaxed finest level, the sphere domain from both sides.
    EXPECT_EQ(count(html, "<img"), 3 + 1 + 2);
    EXPECT_EQ(count(html, "class='note'"), 0) << html.substr(0, 4000);
  } else {
    EXPECT_EQ(count(html, "<img"), 0);
    EXPECT_GE(count(html, "No 3D renders"), 1);
  }
}

TEST(RemeshPage, WithoutRendersTheNotesReplaceThePictures) {
  const Remeshed& r = remeshed();
  reports::RemeshPageOptions options;
  options.renders = false;
  const std::string html = reports::remesh_report_html(r.relaxed, options);
  for (const char* section : kSections) EXPECT_EQ(count(html, section), 1) << section;
  EXPECT_EQ(count(html, "<img"), 0);
  EXPECT_EQ(count(html, "No 3D renders of the levels and the domain: 3D renders were turned off."), 1);
  EXPECT_EQ(count(html, "No picture of the domain"), 1);
  EXPECT_EQ(count(html, "<svg"), 2);
  // remesh computed the stats of each level itself, distance included.
  EXPECT_EQ(count(html, "The geometric error needs the input surface"), 0);
}

TEST(RemeshPage, AGivenInputLocatorIsUsedForTheDistances) {
  const Remeshed& r = remeshed();
  RemeshOptions o;
  o.levels = 2;
  o.base_vertices = 24;
  o.compute_stats = false;  // the page measures the distances itself
  const RemeshResult result = remesh(r.input, o);
  reports::RemeshPageOptions options;
  options.renders = false;
  options.input = &r.input;
  const std::string own = reports::remesh_report_html(result, options);
  EXPECT_EQ(count(own, "–</td>"), 0) << "a distance cell is empty";
  const SurfaceLocator locator(r.input);
  options.input_locator = &locator;
  EXPECT_EQ(reports::remesh_report_html(result, options), own);
  // A locator on another surface changes the distances: the page really queries it.
  TriMesh larger = r.input;
  larger.V *= 1.5;
  const SurfaceLocator other(larger);
  options.input_locator = &other;
  EXPECT_NE(reports::remesh_report_html(result, options), own);
}

TEST(RemeshPage, StretchIsTheAreaRatio) {
  // One level whose 3D positions are its domain positions scaled by 3: stretch 9 on every face.
  RemeshResult r;
  const TriMesh base = icosahedron(1.0);
  r.connectivity = subdivide_connectivity(base.F, static_cast<int>(base.V.rows()), 0);
  RemeshLevel level;
  level.domain_positions = base.V;
  level.positions = 3.0 * base.V;
  r.levels.push_back(level);
  for (double s : reports::face_stretch(r, 0)) EXPECT_NEAR(s, 9.0, 1e-12);
}

TEST(RemeshPage, RemeshCliWritesThePageWithoutADisplay) {
  const fs::path dir = test::scratch_dir("remesh-page");
  write_mesh((dir / "sphere.vtp").string(), icosphere(3, 10.0));
  const auto r = run_without_display("remesh " + (dir / "sphere.vtp").string() + " -o " + (dir / "out").string() +
                                     " --levels 2 --base-vertices 24 --compare-unrelaxed");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string html = read_text(dir / "out" / "report.html");
  for (const char* section : kSections) EXPECT_EQ(count(html, section), 1) << section;
  EXPECT_EQ(count(html, "no DISPLAY is set"), 2);  // the levels and the domain
  EXPECT_EQ(count(html, "<img"), 0);
  EXPECT_EQ(count(html, "<td>unrelaxed</td>"), 3);
  EXPECT_EQ(count(html, "<svg"), 4);
  fs::remove_all(dir);
}

TEST(RemeshPage, BuildModelWritesThePageInsideTheModel) {
  const fs::path dir = test::scratch_dir("build-model-page");
  auto r = test::run_mrsnake("synth --shape ellipsoid --size 32 --noise none -o " + (dir / "case").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path model = dir / "m.model";
  r = test::run_mrsnake("build-model --labels " + (dir / "case" / "truth.nii.gz").string() +
                        " --label 1 --faces 2048 -o " + model.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  ASSERT_TRUE(fs::exists(model / "report.html"));
  const std::string html = read_text(model / "report.html");
  for (const char* s : {"<h2>Settings</h2>", "<h2>Quality per level</h2>", "<h2>Levels</h2>", "<h2>Timings</h2>"})
    EXPECT_EQ(count(html, s), 1) << s;
  EXPECT_EQ(count(html, "–</td>"), 0) << "build-model computes no stats; the page must";
  EXPECT_EQ(count(html, "<td>marching_cubes</td>"), 1);
  if (reports::display_available()) {
    EXPECT_GE(count(html, "<img"), 3);
  }
  // The model still loads and checks: the page is not part of the manifest.
  r = test::run_mrsnake("model-info " + model.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  // No temporary folder is left beside the model.
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) entries += e.path().filename() != "case";
  EXPECT_EQ(entries, 1);
  fs::remove_all(dir);
}

namespace {

/// A 32³ volume, bright inside a sphere of radius 9 around the centre, with its truth labels.
struct SegmentCase {
  Volume image, truth;
  TriMesh surface = icosphere(3, 9.0);
  SegmentCase() {
    image.size = truth.size = {32, 32, 32};
    image.spacing = truth.spacing = {1, 1, 1};
    image.data.assign(image.num_voxels(), 0.f);
    truth.data.assign(truth.num_voxels(), 0.f);
    for (std::size_t k = 0; k < 32; ++k)
      for (std::size_t j = 0; j < 32; ++j)
        for (std::size_t i = 0; i < 32; ++i) {
          const double r = std::hypot(i - 15.5, j - 15.5, k - 15.5);
          image.at(i, j, k) = r < 9 ? 100.f : 10.f;
          truth.at(i, j, k) = r < 9 ? 1.f : 0.f;
        }
    surface.V.rowwise() += Eigen::RowVector3d(15.5, 15.5, 15.5);
  }
  reports::SegmentPageInput input() const {
    reports::SegmentPageInput in;
    in.image = &image;
    in.surface = &surface;
    in.truth = &truth;
    for (int j = 0; j < 3; ++j)
      in.convergence.push_back({j, {3, 2, 1.5, 1.4}, {2, 1.5, 1.1, 1.0}, {1, 0.5, 0.4, 0.4}, {2.0, 1.0, 0.5, 0.4}});
    in.report = {{"force", "step_edge"},
                 {"scores", {{"dice", 0.95}}},
                 {"levels", {{{"level", 0}, {"iterations", 4}}, {{"level", 1}, {"iterations", 4}}}},
                 {"stage_seconds", {{"load", 0.1}, {"snake", 0.5}}}};
    return in;
  }
};

const char* kSegmentSections[] = {"<h2>Summary</h2>",     "<h2>Scores against the truth</h2>",
                                  "<h2>Slices</h2>",      "<h2>Surface</h2>",
                                  "<h2>Convergence</h2>", "<h2>Levels</h2>",
                                  "<h2>Timings</h2>"};

}  // namespace

TEST(SegmentPage, EverySectionAndPicture) {
  const SegmentCase c;
  const std::string html = reports::segment_report_html(c.input());
  for (const char* section : kSegmentSections) EXPECT_EQ(count(html, section), 1) << section;
  EXPECT_EQ(count(html, "<svg"), 3 + 1);  // energy per level, offsets of all levels
  EXPECT_EQ(count(html, "truth&#39;s outline in green"), 1);
  EXPECT_EQ(count(html, "<td>dice</td><td>0.95</td>"), 1);
  if (reports::display_available()) {
    EXPECT_EQ(count(html, "<img"), 3 + 2);  // three slices, the surface from two sides
    EXPECT_EQ(count(html, "class='note'"), 0);
  } else {
    EXPECT_EQ(count(html, "<img"), 3);
    EXPECT_EQ(count(html, "No 3D render of the surface"), 1);
  }
}

TEST(SegmentPage, WithoutRendersOrHistoryTheNotesSaySo) {
  const SegmentCase c;
  reports::SegmentPageInput in = c.input();
  in.renders = false;
  in.truth = nullptr;
  in.convergence.clear();
  in.report = nlohmann::json::object();
  const std::string html = reports::segment_report_html(in);
  EXPECT_EQ(count(html, "<img"), 3);  // the slices need no display
  EXPECT_EQ(count(html, "No 3D render of the surface: 3D renders were turned off."), 1);
  EXPECT_EQ(count(html, "No convergence history was recorded."), 1);
  EXPECT_EQ(count(html, "No timings were recorded."), 1);
  EXPECT_EQ(count(html, "<svg"), 0);
  EXPECT_THROW(reports::segment_report_html(reports::SegmentPageInput{}), std::invalid_argument);
}

TEST(SegmentPage, APictureThatFailsBecomesANote) {
  const SegmentCase c;
  reports::SegmentPageInput in = c.input();
  in.renders = false;
  in.convergence = {{0, {}, {}, {}, {}}};  // a level without iterations
  const std::string html = reports::segment_report_html(in);
  EXPECT_EQ(count(html, "The convergence plot of level 0 could not be drawn: no iterations were recorded"), 1);
  EXPECT_EQ(count(html, "The offset plot could not be drawn"), 1);
}
