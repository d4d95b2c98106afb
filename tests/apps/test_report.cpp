#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cmath>

#include "apps/report/canvas.h"
#include "apps/report/html.h"
#include "apps/report/plots.h"
#include "apps/report/render.h"
#include "apps/report/slices.h"
#include "mesh/errors.h"
#include "mesh/primitives.h"
#include "tests/test_support.h"

using namespace mrsnake;
using namespace mrsnake::reports;

namespace {
bool is_png(const std::vector<std::uint8_t>& b) {
  return b.size() > 8 && b[0] == 0x89 && b[1] == 'P' && b[2] == 'N' && b[3] == 'G';
}
}  // namespace

TEST(Report, Base64KnownVectors) {
  const auto b = [](const std::string& s) { return base64(std::vector<std::uint8_t>(s.begin(), s.end())); };
  EXPECT_EQ(b("Man"), "TWFu");
  EXPECT_EQ(b("Ma"), "TWE=");
  EXPECT_EQ(b("M"), "TQ==");
  EXPECT_EQ(b(""), "");
}

TEST(Report, CanvasLinesAndPng) {
  Canvas c(20, 10);
  c.line(0, 5, 19, 5, {255, 0, 0});
  EXPECT_EQ(c.get(10, 5).r, 255);
  EXPECT_EQ(c.get(10, 2).r, 0);
  EXPECT_TRUE(is_png(c.png()));
}

TEST(Report, SliceDrawsTheSphereContourAtItsRadius) {
  Volume image;
  image.size = {40, 40, 40};
  image.spacing = {1, 1, 1};
  image.data.assign(image.num_voxels(), 0.f);
  const TriMesh sphere = [] {
    TriMesh s = icosphere(4, 10.0);
    s.V.rowwise() += Eigen::RowVector3d(19.5, 19.5, 19.5);
    return s;
  }();
  const Canvas c = slice_with_contours(image, 2, 19.5, {{&sphere, {255, 0, 0}, "surface"}}, {}, 40);
  ASSERT_EQ(c.width(), 40);
  // The contour crosses the horizontal midline at x = centre ± radius, not at the centre.
  int red_near_radius = 0;
  for (int x = 0; x < 40; ++x)
    for (int y = 18; y <= 21; ++y)
      if (c.get(x, y).r == 255 && c.get(x, y).g == 0) {
        EXPECT_NEAR(std::abs(x + 0.5 - 20.0), 10.0, 1.6) << "x=" << x;
        ++red_near_radius;
      }
  EXPECT_GT(red_near_radius, 0);
}

TEST(Report, LabelOutlineFollowsTheLabel) {
  Volume image, labels;
  image.size = labels.size = {10, 10, 3};
  image.data.assign(image.num_voxels(), 0.f);
  labels.data.assign(labels.num_voxels(), 0.f);
  for (std::size_t j = 3; j < 7; ++j)
    for (std::size_t i = 3; i < 7; ++i) labels.at(i, j, 1) = 1.f;
  const Canvas c = slice_with_contours(image, 2, 1, {}, {{&labels, 1.f, {0, 255, 0}, "truth"}}, 10);
  EXPECT_EQ(c.get(3, 5).g, 255);  // on the outline
  EXPECT_EQ(c.get(5, 5).g, 0);    // inside: not drawn
  EXPECT_EQ(c.get(1, 5).g, 0);    // outside
}

TEST(Report, HtmlEmbedsPicturesAndEscapesText) {
  HtmlPage page("Report <test>");
  page.table({"a", "b"}, {{"1", "<2>"}});
  Canvas c(4, 4);
  page.png(c.png(), "tiny");
  page.svg(svg_histogram({1, 2, 2, 3}, 3, 0, 0, "h", "x"), "hist");
  page.svg(svg_line_plot({{"energy", {0, 1, 2}, {3, 2, 1}}}, "plot", "iteration", "energy", true), "plot");
  const std::string html = page.str();
  EXPECT_NE(html.find("data:image/png;base64,iVBORw0KGgo"), std::string::npos);
  EXPECT_NE(html.find("&lt;2&gt;"), std::string::npos);
  EXPECT_NE(html.find("Report &lt;test&gt;"), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_EQ(html.find("<2>"), std::string::npos);
}

TEST(Report, RenderNeedsADisplayAndMakesAPng) {
  std::string why;
  if (!display_available(&why)) GTEST_SKIP() << "no 3D render test: " << why;
  RenderOptions options;
  options.face_scalars.assign(icosphere(2).num_faces(), 1.0);
  options.face_scalars[0] = 10.0;
  options.scalar_title = "density";
  const auto png = render_mesh_png(icosphere(2), options);
  EXPECT_TRUE(is_png(png));
  if (const char* keep = std::getenv("MRSNAKE_KEEP_RENDER")) {
    FILE* f = std::fopen(keep, "wb");
    std::fwrite(png.data(), 1, png.size(), f);
    std::fclose(f);
  }
}

TEST(Report, ARenderOutlastingItsTimeIsStoppedAndLaterOnesAreLeftOut) {
  // A render that hangs (a stalled display, a lock held at the fork) must cost its picture,
  // not the program: the child is killed and reaped at the deadline, and the process stops
  // asking a renderer that did not answer.
  std::string why;
  if (!display_available(&why)) GTEST_SKIP() << "no 3D render test: " << why;
  RenderOptions options;
  options.max_seconds = 0;  // every render outlasts it
  const auto start = std::chrono::steady_clock::now();
  try {
    render_mesh_png(icosphere(3), options);
    ADD_FAILURE() << "a render past its deadline returned a picture";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("did not finish within 0 s"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
  // The child was reaped: this process has no child left, not even a zombie.
  EXPECT_EQ(waitpid(-1, nullptr, WNOHANG), -1);
  EXPECT_EQ(errno, ECHILD);
  EXPECT_FALSE(display_available(&why));
  EXPECT_NE(why.find("did not finish"), std::string::npos) << why;
  EXPECT_THROW(render_mesh_png(icosphere(1)), Error);
}
