// SegmentOptions as JSON (snake/segment.h, mesh/json_options.h): the round trip, the keys
// refused, and `mrsnake segment --config` with a report's own "options".
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/json_options.h"
#include "mesh/mesh_io.h"
#include "snake/segment.h"
#include "tests/test_support.h"

namespace mrsnake {
namespace {

TEST(SegmentOptionsJson, TheDefaultsRoundTrip) {
  const nlohmann::json written = SegmentOptions{};
  EXPECT_EQ(written["init"], "auto");
  EXPECT_EQ(written["force"], "auto");
  EXPECT_EQ(written["registration"]["itk"]["metric"], "mattes");
  EXPECT_TRUE(written["moments"]["threshold"].is_null());  // NaN: Otsu's threshold
  const SegmentOptions read = options_from_json<SegmentOptions>(written);
  EXPECT_EQ(nlohmann::json(read), written);
  EXPECT_TRUE(std::isnan(read.moments.threshold));
  // Parsed from its text too, as --config reads it.
  EXPECT_EQ(nlohmann::json(options_from_json<SegmentOptions>(nlohmann::json::parse(written.dump()))), written);
  // An empty object is the defaults.
  EXPECT_EQ(nlohmann::json(options_from_json<SegmentOptions>(nlohmann::json::object())), written);
}

TEST(SegmentOptionsCheck, TheDefaultsPassAndAValueOutOfRangeIsRefusedByItsKey) {
  EXPECT_NO_THROW(check_options(SegmentOptions{}));
  struct Case {
    const char* key;
    void (*spoil)(SegmentOptions&);
  };
  const Case cases[] = {
      {"snake.max_iterations is -1", [](SegmentOptions& o) { o.snake.max_iterations = -1; }},
      {"snake.time_step is 0", [](SegmentOptions& o) { o.snake.time_step = 0; }},
      {"snake.external_weight is -1", [](SegmentOptions& o) { o.snake.external_weight = -1; }},
      {"step_voxels is nan", [](SegmentOptions& o) { o.step_voxels = std::nan(""); }},
      {"step_voxels is 0", [](SegmentOptions& o) { o.step_voxels = 0; }},
      {"snake.max_iterations is 100001", [](SegmentOptions& o) { o.snake.max_iterations = 100001; }},
      {"registration.itk.shrink_factors[] is 0", [](SegmentOptions& o) { o.registration.itk.shrink_factors[0] = 0; }},
      {"fit_level is -3", [](SegmentOptions& o) { o.fit_level = -3; }},
      {"fit.trim_fraction is 1", [](SegmentOptions& o) { o.fit.trim_fraction = 1; }},
      {"fine.profile_step_fraction is -0.5", [](SegmentOptions& o) { o.fine.profile_step_fraction = -0.5; }},
      {"registration.max_scale is 0.4", [](SegmentOptions& o) { o.registration.max_scale = 0.4; }},
      {"intensity_samples is 1000", [](SegmentOptions& o) { o.intensity_samples = 1000; }},
  };
  for (const Case& c : cases) {
    SegmentOptions o;
    c.spoil(o);
    try {
      check_options(o);
      ADD_FAILURE() << c.key << ": accepted";
    } catch (const OptionsError& e) {
      EXPECT_NE(std::string(e.what()).find(c.key), std::string::npos) << e.what();
    }
  }
}

TEST(SegmentOptionsJson, ChangedValuesRoundTripExactly) {
  SegmentOptions o;
  o.init = InitMode::registration_and_fit;
  o.force = ForceMode::step_edge;
  o.registration.itk.metric = RegistrationMetric::mean_squares;
  o.registration.itk.shrink_factors = {2, 1};
  o.moments.threshold = 0.1;
  o.snake.max_iterations = 7;
  o.snake.external_weight = 1.0 / 3.0;
  o.fine.patience = 5;
  o.intensity_samples = 12345;
  o.max_range_voxels = 3.3;
  o.undo_self_intersections = false;
  const SegmentOptions r = options_from_json<SegmentOptions>(nlohmann::json::parse(nlohmann::json(o).dump()));
  EXPECT_EQ(r.init, o.init);
  EXPECT_EQ(r.force, o.force);
  EXPECT_EQ(r.registration.itk.metric, o.registration.itk.metric);
  EXPECT_EQ(r.registration.itk.shrink_factors, o.registration.itk.shrink_factors);
  EXPECT_EQ(r.moments.threshold, o.moments.threshold);
  EXPECT_EQ(r.snake.max_iterations, 7);
  EXPECT_EQ(r.snake.external_weight, o.snake.external_weight);  // bit for bit
  EXPECT_EQ(r.fine.patience, 5);
  EXPECT_EQ(r.intensity_samples, 12345u);
  EXPECT_EQ(r.max_range_voxels, 3.3);
  EXPECT_FALSE(r.undo_self_intersections);
  EXPECT_EQ(nlohmann::json(r), nlohmann::json(o));
}

// The InputError's message (empty when none is thrown).
std::string input_error(const nlohmann::json& j) {
  try {
    (void)options_from_json<SegmentOptions>(j);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SegmentOptionsJson, AnUnknownKeyIsRefusedByName) {
  EXPECT_NE(input_error({{"fit_levels", 2}}).find("'fit_levels'"), std::string::npos);
  EXPECT_NE(input_error({{"snake", {{"max_iteration", 3}}}}).find("'snake.max_iteration'"), std::string::npos);
  EXPECT_NE(input_error({{"registration", {{"itk", {{"bins", 3}}}}}}).find("'registration.itk.bins'"),
            std::string::npos);
  // Not a key but a value: an enum name that is none of the command line's, a wrong type.
  EXPECT_NE(input_error({{"init", "magic"}}).find("magic"), std::string::npos);
  EXPECT_FALSE(input_error({{"fit_level", "two"}}).empty());
  EXPECT_FALSE(input_error({{"snake", 3}}).empty());
  // From a file, the message names the file too.
  const auto dir = mrsnake::test::scratch_dir("segment-options");
  const std::string path = (dir / "options.json").string();
  std::ofstream(path) << R"({"fine": {"patience": 1, "patiense": 2}})";
  try {
    (void)read_options_file<SegmentOptions>(path);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'fine.patiense'"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

TEST(SegmentCommand, ConfigFromAReportsOptionsReproducesTheSurface) {
  const auto dir = mrsnake::test::scratch_dir("segment-config");
  const std::string d = dir.string();
  for (const auto& [name, extra] :
       {std::pair<std::string, std::string>{"ref", "--seed 5"}, {"tgt", "--seed 6 --pose random"}}) {
    const auto r =
        mrsnake::test::run_mrsnake("-q synth --shape blob --size 40 --snr 6 " + extra + " -o " + d + "/" + name);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const auto b = mrsnake::test::run_mrsnake("-q build-model --labels " + d + "/ref/truth.nii.gz --label 1 --image " +
                                            d + "/ref/image.nii.gz --faces 2000 -o " + d + "/blob.model");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const std::string segment = "-q segment --image " + d + "/tgt/image.nii.gz --model " + d + "/blob.model";
  // Flags away from the defaults, which report.json's "options" must carry.
  const auto first = mrsnake::test::run_mrsnake(segment + " -o " + d +
                                                "/first --init moments+fit --force profile --max-iterations 10");
  ASSERT_EQ(first.exit_code, 0) << first.output;
  std::ifstream first_in(dir / "first" / "report.json");
  const nlohmann::json options = nlohmann::json::parse(first_in)["options"];
  EXPECT_EQ(options["init"], "moments+fit");
  EXPECT_EQ(options["force"], "profile");
  EXPECT_EQ(options["snake"]["max_iterations"], 10);
  std::ofstream(dir / "options.json") << options.dump(2);

  const auto again = mrsnake::test::run_mrsnake(segment + " -o " + d + "/again --config " + d + "/options.json");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const TriMesh a = read_mesh((dir / "first" / "surface.vtp").string());
  const TriMesh r = read_mesh((dir / "again" / "surface.vtp").string());
  ASSERT_EQ(a.V.rows(), r.V.rows());
  EXPECT_TRUE(a.V == r.V) << "the vertices differ: max " << (a.V - r.V).cwiseAbs().maxCoeff() << " mm";
  EXPECT_TRUE(a.F == r.F);
  std::ifstream again_in(dir / "again" / "report.json");
  EXPECT_EQ(nlohmann::json::parse(again_in)["options"], options);

  // A flag given replaces the file's value; the others stay the file's.
  const auto flagged =
      mrsnake::test::run_mrsnake(segment + " -o " + d + "/flagged --config " + d + "/options.json --max-iterations 3");
  ASSERT_EQ(flagged.exit_code, 0) << flagged.output;
  std::ifstream flagged_in(dir / "flagged" / "report.json");
  const nlohmann::json flagged_options = nlohmann::json::parse(flagged_in)["options"];
  EXPECT_EQ(flagged_options["snake"]["max_iterations"], 3);
  EXPECT_EQ(flagged_options["init"], "moments+fit");
  EXPECT_EQ(flagged_options["force"], "profile");

  // A misspelt key: exit code 3, naming it, and nothing written.
  std::ofstream(dir / "bad.json") << R"({"snake": {"max_iteration": 3}})";
  const auto bad = mrsnake::test::run_mrsnake(segment + " -o " + d + "/bad --config " + d + "/bad.json");
  EXPECT_EQ(bad.exit_code, 3) << bad.output;
  EXPECT_NE(bad.output.find("snake.max_iteration"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad"));
  // A value out of range (a negative level names no level of the mesh): the same, before any work.
  std::ofstream(dir / "range.json") << R"({"fit_level": -3})";
  const auto range = mrsnake::test::run_mrsnake(segment + " -o " + d + "/range --config " + d + "/range.json");
  EXPECT_EQ(range.exit_code, 3) << range.output;
  EXPECT_NE(range.output.find("fit_level is -3"), std::string::npos) << range.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "range"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mrsnake
