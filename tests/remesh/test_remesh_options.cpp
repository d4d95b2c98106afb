// Tests of RemeshOptions as JSON: `mrsnake remesh --config` and report.json's "options".
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/json_options.h"
#include "mesh/mesh_io.h"
#include "remesh/remesh.h"
#include "remesh/remesh_options_json.h"
#include "tests/remesh/remesh_shapes.h"
#include "tests/test_support.h"

namespace mrsnake {
namespace {

using test::ellipsoid;

nlohmann::json read_json(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

void write_json(const std::filesystem::path& path, const nlohmann::json& j) { std::ofstream(path) << j.dump(2); }

std::string message_of_refusal(const nlohmann::json& j) {
  try {
    options_from_json<RemeshOptions>(j);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

TEST(RemeshOptionsJson, DefaultsRoundTrip) {
  const nlohmann::json defaults = RemeshOptions{};
  EXPECT_EQ(nlohmann::json(options_from_json<RemeshOptions>(defaults)), defaults);
  // Every stage's options are there, nested, and the enums are strings.
  for (const char* key : {"simplify", "sizing", "base", "relaxation", "snap", "repair", "fit", "untangle"})
    EXPECT_TRUE(defaults.at(key).is_object()) << key;
  EXPECT_EQ(defaults.at("relax"), "all_vertices");
  EXPECT_EQ(defaults.at("sphere_map"), "automatic");
  EXPECT_EQ(defaults.at("relaxation").at("lloyd_iterations"), 8);
  // The caller-only fields are not part of it.
  EXPECT_FALSE(defaults.contains("compute_stats"));
  EXPECT_FALSE(defaults.contains("keep_input_locator"));
  EXPECT_FALSE(defaults.contains("progress"));
}

TEST(RemeshOptionsJson, GivenKeysReplaceDefaultsAndRoundTrip) {
  const nlohmann::json given = {{"levels", 2},
                                {"relax", "new_vertices_only"},
                                {"sphere_map", "two_halves"},
                                {"base_mesh_alone_when_squeezed", false},
                                {"sizing", {{"curvature_weight", 0.7}}},
                                {"repair", {{"threshold", 0.8}, {"coarse_levels", false}}},
                                {"fit", {{"rounds", 2}}}};
  const RemeshOptions o = options_from_json<RemeshOptions>(given);
  EXPECT_EQ(o.levels, 2);
  EXPECT_EQ(o.relax, RelaxMode::new_vertices_only);
  EXPECT_EQ(o.sphere_map, SphereMap::two_halves);
  EXPECT_TRUE(RemeshOptions{}.base_mesh_alone_when_squeezed);
  EXPECT_FALSE(o.base_mesh_alone_when_squeezed);
  EXPECT_EQ(o.sizing.curvature_weight, 0.7);
  EXPECT_EQ(o.sizing.curvature_exponent, RemeshOptions{}.sizing.curvature_exponent);
  EXPECT_EQ(o.repair.threshold, 0.8);
  EXPECT_FALSE(o.repair.coarse_levels);
  EXPECT_EQ(o.repair.sweeps, RemeshOptions{}.repair.sweeps);
  EXPECT_EQ(o.fit.rounds, 2);
  const nlohmann::json written = o;
  EXPECT_EQ(nlohmann::json(options_from_json<RemeshOptions>(written)), written);
}

TEST(RemeshOptionsJson, RefusesUnknownKeysAndValues) {
  // A misspelt nested key, and a flat (un-nested) name, are named in the message.
  EXPECT_NE(message_of_refusal({{"relaxation", {{"lloyd_iteration", 3}}}}).find("relaxation.lloyd_iteration"),
            std::string::npos);
  EXPECT_NE(message_of_refusal({{"lloyd_iterations", 3}}).find("'lloyd_iterations'"), std::string::npos);
  EXPECT_THROW(options_from_json<RemeshOptions>({{"relax", "some"}}), InputError);
  EXPECT_NE(message_of_refusal({{"relax", "some"}}).find("new_vertices_only"), std::string::npos);
  EXPECT_THROW(options_from_json<RemeshOptions>({{"sphere_map", "halves"}}), InputError);
  EXPECT_THROW(options_from_json<RemeshOptions>({{"levels", "two"}}), InputError);
  EXPECT_THROW(options_from_json<RemeshOptions>({{"repair", 3}}), InputError);
}

TEST(RemeshOptionsJson, ReportRecordsTheOptions) {
  RemeshOptions o;
  o.levels = 1;
  o.base_vertices = 12;
  o.relaxation.lloyd_iterations = 3;
  o.compute_stats = false;
  const RemeshResult r = remesh(ellipsoid(2), o);
  const nlohmann::json report = remesh_report(r, o);
  EXPECT_EQ(report.at("options"), nlohmann::json(o));
  EXPECT_EQ(report.at("options").at("relaxation").at("lloyd_iterations"), 3);
  EXPECT_EQ(report.at("lloyd_iterations"), 3);
  // The guarded shape sweeps run on the base-mesh domain only.
  ASSERT_EQ(r.domain, "sphere");
  EXPECT_EQ(report.at("guarded_shape_iterations"), 0);
}

// The command line: --config FILE, flags over the file, and a run repeated from its report.
class RemeshConfigCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::scratch_dir("remesh-config");
    input_ = (dir_ / "ellipsoid.off").string();
    write_mesh(input_, ellipsoid(3));
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Runs `remesh INPUT -o DIR/out args` and returns DIR/out.
  std::filesystem::path run(const std::string& out, const std::string& args) {
    const auto path = dir_ / out;
    const auto r = test::run_mrsnake("-q remesh " + input_ + " -o " + path.string() + " " + args);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return path;
  }

  std::filesystem::path dir_;
  std::string input_;
};

TEST_F(RemeshConfigCli, ConfigFileChangesAFieldAndTheReportShowsIt) {
  write_json(dir_ / "config.json", {{"levels", 2}, {"base_vertices", 12}, {"relaxation", {{"lloyd_iterations", 3}}}});
  const auto out = run("a", "--config " + (dir_ / "config.json").string());
  const nlohmann::json report = read_json(out / "report.json");
  EXPECT_EQ(report["options"]["relaxation"]["lloyd_iterations"], 3);
  EXPECT_EQ(report["lloyd_iterations"], 3);
  EXPECT_EQ(report["levels"], 2);
  EXPECT_EQ(report["parameterization"]["base_vertices"], 12);
  // Flags given explicitly override the file.
  write_json(dir_ / "fit.json", {{"levels", 2}, {"base_vertices", 12}, {"fit", {{"rounds", 0}}}});
  const nlohmann::json overridden =
      read_json(run("b", "--config " + (dir_ / "fit.json").string() + " --fit-rounds 2 --strict") / "report.json");
  EXPECT_EQ(overridden["options"]["fit"]["rounds"], 2);
  EXPECT_EQ(overridden["options"]["relax"], "new_vertices_only");
  EXPECT_EQ(overridden["options"]["levels"], 2);
  // The options file's names of the sphere map are the flag's too.
  EXPECT_EQ(read_json(run("halves", "--faces 512 --sphere-map two_halves") / "report.json")["options"]["sphere_map"],
            "two_halves");
  const nlohmann::json by_faces =
      read_json(run("c", "--config " + (dir_ / "fit.json").string() + " --faces 512") / "report.json");
  EXPECT_EQ(by_faces["options"]["levels"], 0);
  EXPECT_EQ(by_faces["options"]["target_faces"], 512);
  EXPECT_EQ(by_faces["options"]["fit"]["rounds"], 0);
  // An unknown key is refused before any work, naming it (usage error).
  write_json(dir_ / "bad.json", {{"relaxation", {{"lloyd", 3}}}});
  const auto bad = test::run_mrsnake("-q remesh " + input_ + " -o " + (dir_ / "bad").string() + " --config " +
                                     (dir_ / "bad.json").string());
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("relaxation.lloyd"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bad"));
  // A value out of range is refused the same way, naming its key and its range.
  write_json(dir_ / "deep.json", {{"levels", 20}});
  const auto deep = test::run_mrsnake("-q remesh " + input_ + " -o " + (dir_ / "deep").string() + " --config " +
                                      (dir_ / "deep.json").string());
  EXPECT_EQ(deep.exit_code, 3) << deep.output;
  EXPECT_NE(deep.output.find("levels is 20; it must be in [0, 12]"), std::string::npos) << deep.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "deep"));
  write_json(dir_ / "base.json", {{"domain", "base_mesh"}});
  const auto strict = test::run_mrsnake("-q remesh " + input_ + " -o " + (dir_ / "strict").string() + " --config " +
                                        (dir_ / "base.json").string() + " --strict");
  EXPECT_EQ(strict.exit_code, 3) << strict.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "strict"));
}

// The message of check_options(o, at), or "" if it accepts them.
std::string refusal(const RemeshOptions& o, const std::string& at = "") {
  try {
    check_options(o, at);
  } catch (const OptionsError& e) {
    return e.what();
  }
  return "";
}

TEST(RemeshOptionsCheck, ThePapersExactMethodIsRefusedOnTheBaseMeshDomainOnly) {
  RemeshOptions o;
  EXPECT_EQ(refusal(o), "");
  o.relax = RelaxMode::new_vertices_only;
  EXPECT_EQ(refusal(o), "");  // the sphere domain has it
  o.domain = ParameterDomain::base_mesh;
  EXPECT_NE(refusal(o, "remesh.").find("remesh.relax new_vertices_only"), std::string::npos) << refusal(o);
  EXPECT_THROW(remesh(ellipsoid(2), o), OptionsError);
}

TEST(RemeshOptionsCheck, AValueOutOfRangeIsRefusedByItsKeyWithThePrefix) {
  RemeshOptions o;
  o.relaxation.surface_quality_floor = 1.5;
  EXPECT_EQ(refusal(o, "remesh."), "the option remesh.relaxation.surface_quality_floor is 1.5; it must be in [0, 1]");
  o = RemeshOptions{};
  o.fit.regularization = 0;
  EXPECT_EQ(refusal(o), "the option fit.regularization is 0; it must be a positive number");
  o = RemeshOptions{};
  o.untangle.max_rounds = -1;
  EXPECT_EQ(refusal(o), "the option untangle.max_rounds is -1; it must be at least 0");
}

TEST_F(RemeshConfigCli, ReportOptionsRepeatTheRunExactly) {
  write_json(dir_ / "config.json", {{"sizing", {{"curvature_weight", 1.0}}}, {"repair", {{"threshold", 0.8}}}});
  const auto first = run("first", "--levels 2 --base-vertices 12 --config " + (dir_ / "config.json").string());
  const nlohmann::json report = read_json(first / "report.json");
  write_json(dir_ / "repeat.json", report["options"]);
  const auto again = run("again", "--config " + (dir_ / "repeat.json").string());
  EXPECT_EQ(read_json(again / "report.json")["options"], report["options"]);
  for (int j = 0; j <= 2; ++j) {
    const std::string name = "level_" + std::to_string(j) + ".vtp";
    const TriMesh a = read_mesh((first / name).string()), b = read_mesh((again / name).string());
    ASSERT_EQ(a.V.rows(), b.V.rows()) << name;
    EXPECT_TRUE(a.V == b.V) << name << ": the vertex positions differ";
    EXPECT_TRUE(a.F == b.F) << name;
    EXPECT_EQ(test::read_all(first / name), test::read_all(again / name)) << name;
  }
}

TEST(RemeshCli, PrintConfigPrintsTheDefaults) {
  const auto r = test::run_mrsnake("remesh --print-config");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ(nlohmann::json::parse(r.output), nlohmann::json(RemeshOptions{}));
}

}  // namespace
}  // namespace mrsnake
