#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "tests/test_support.h"
#include "tests/wavelets/hierarchies.h"
#include "model/model_io.h"

using namespace mrsnake;
using namespace mrsnake::test;
namespace fs = std::filesystem;

namespace {

ShapeModel sample_model() {
  const Hierarchy h = bumpy_sphere(3);
  ShapeModel m = make_model(h.conn, h.finest);
  m.source_image = "liver-labels.nii.gz";
  m.source_label = 255;
  PhysicalFrame f;
  f.size = {438, 353, 165};
  f.spacing = {0.617, 0.617, 1.333};
  f.origin = {-10.5, 20.25, 3.0};
  m.physical_frame = f;
  m.remesh_quality = {{"q_min", 0.52}, {"min_angle_deg", 31.5}};
  m.timings = {{"read", 0.125}, {"analysis", 0.0031}};
  m.sections["appearance"] = {1, 2, 3, 250, 0, 7};
  return m;
}

using test::read_all;
using test::write_all;

std::string hex(std::uint64_t v) {
  char s[17];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(v));
  return s;
}

/// Rewrites model.json with a consistent checksum (a deliberate, well-formed edit).
void rewrite_manifest(const fs::path& dir, const std::function<void(nlohmann::json&)>& edit) {
  std::ifstream in(dir / "model.json");
  nlohmann::json m = nlohmann::json::parse(in);
  edit(m);
  m.erase("manifest_fnv1a64");
  const std::string text = m.dump();
  m["manifest_fnv1a64"] = hex(fnv1a64(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  std::ofstream(dir / "model.json") << m.dump(2);
}

/// Expects load_model to throw an InputError whose message contains `needle`.
void expect_input_error(const fs::path& dir, const std::string& needle) {
  try {
    load_model(dir.string(), {true});
    ADD_FAILURE() << "no error; expected one mentioning '" << needle << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(ModelIo, SaveThenLoadGivesTheSameModel) {
  const fs::path dir = scratch_dir("model-roundtrip") / "sphere.model";
  const ShapeModel m = sample_model();
  save_model(dir.string(), m);
  for (const char* f : {"model.json", "details.bin", "level_0.vtp", "level_3.vtp", "appearance.bin"})
    EXPECT_TRUE(fs::exists(dir / f)) << f;
  const ShapeModel r = load_model(dir.string(), {true});
  EXPECT_EQ(r.base_faces, m.base_faces);
  EXPECT_EQ(r.base, m.base);  // bit for bit
  ASSERT_EQ(r.details.size(), m.details.size());
  for (std::size_t j = 0; j < m.details.size(); ++j) EXPECT_EQ(r.details[j], m.details[j]);
  ASSERT_EQ(r.level_positions.size(), 4u);
  for (int j = 0; j <= 3; ++j) EXPECT_EQ(r.level_positions[j], m.level_positions[j]);
  EXPECT_EQ(r.wavelet.predict, m.wavelet.predict);
  EXPECT_EQ(r.wavelet.update, m.wavelet.update);
  EXPECT_EQ(r.wavelet.frame, m.wavelet.frame);
  EXPECT_EQ(r.source_image, m.source_image);
  EXPECT_EQ(r.source_label, m.source_label);
  ASSERT_TRUE(r.physical_frame);
  EXPECT_EQ(r.physical_frame->spacing, m.physical_frame->spacing);
  EXPECT_EQ(r.physical_frame->size, m.physical_frame->size);
  EXPECT_EQ(r.remesh_quality, m.remesh_quality);
  EXPECT_EQ(r.timings, m.timings);
  EXPECT_EQ(r.sections, m.sections);
  ASSERT_EQ(r.detail_stats.size(), 3u);
  EXPECT_EQ(r.detail_stats[2].rms, m.detail_stats[2].rms);
  EXPECT_LE(max_row_distance(synthesize(r), m.level_positions[3]), 1e-9 * bounding_box_diagonal(m.level_positions[3]));
  // Linear, global, no update: the scheme round-trips too.
  ShapeModel lin = make_model(bumpy_cap(2).conn, bumpy_cap(2).finest,
                              WaveletOptions{PredictScheme::linear, false, DetailFrame::global, 1e-10});
  save_model(dir.string(), lin);  // replaces the existing model
  const ShapeModel rl = load_model(dir.string());
  EXPECT_EQ(rl.wavelet.predict, PredictScheme::linear);
  EXPECT_FALSE(rl.wavelet.update);
  EXPECT_EQ(rl.wavelet.frame, DetailFrame::global);
  EXPECT_FALSE(rl.source_label);
  EXPECT_TRUE(rl.level_positions.empty());
  EXPECT_LE(max_row_distance(synthesize(rl), bumpy_cap(2).finest), 1e-9 * bounding_box_diagonal(bumpy_cap(2).finest));
  // Nothing temporary is left beside it.
  for (const auto& e : fs::directory_iterator(dir.parent_path())) EXPECT_EQ(e.path().filename(), "sphere.model");
}

TEST(ModelIo, RefusesToReplaceSomethingThatIsNotAModel) {
  const fs::path dir = scratch_dir("model-refuse");
  std::ofstream(dir / "notes.txt") << "keep me";
  fs::create_directories(dir / "folder");
  std::ofstream(dir / "folder" / "data.txt") << "keep me";
  EXPECT_THROW(save_model((dir / "notes.txt").string(), sample_model()), OutputError);
  EXPECT_THROW(save_model((dir / "folder").string(), sample_model()), OutputError);
  EXPECT_TRUE(fs::exists(dir / "folder" / "data.txt"));
  EXPECT_TRUE(fs::is_regular_file(dir / "notes.txt"));
}

TEST(ModelIo, EveryDamageGetsASpecificError) {
  const fs::path root = scratch_dir("model-damage");
  const ShapeModel m = sample_model();
  const auto fresh = [&](const std::string& name) {
    const fs::path dir = root / name;
    save_model(dir.string(), m);
    return dir;
  };
  {  // truncated binary part
    const fs::path dir = fresh("truncated");
    auto b = read_all(dir / "details.bin");
    b.resize(b.size() - 100);
    write_all(dir / "details.bin", b);
    expect_input_error(dir, "is truncated");
  }
  {  // one flipped byte in the details
    const fs::path dir = fresh("flipped");
    auto b = read_all(dir / "details.bin");
    b[b.size() / 2] ^= 0x10;
    write_all(dir / "details.bin", b);
    expect_input_error(dir, "'details.bin' of model");
    expect_input_error(dir, "altered or corrupted");
  }
  {  // a flipped byte that the manifest also re-registers: the binary's own checksum catches it
    const fs::path dir = fresh("flipped-resummed");
    auto b = read_all(dir / "details.bin");
    b[b.size() / 2] ^= 0x01;
    write_all(dir / "details.bin", b);
    rewrite_manifest(dir,
                     [&](nlohmann::json& j) { j["files"]["details"]["fnv1a64"] = hex(fnv1a64(b.data(), b.size())); });
    expect_input_error(dir, "its checksum does not match");
  }
  {  // an altered level mesh
    const fs::path dir = fresh("level");
    auto b = read_all(dir / "level_2.vtp");
    b[b.size() - 10] ^= 0x04;
    write_all(dir / "level_2.vtp", b);
    expect_input_error(dir, "part 'level_2.vtp'");
  }
  {  // an edited manifest
    const fs::path dir = fresh("manifest-edit");
    std::ifstream in(dir / "model.json");
    nlohmann::json j = nlohmann::json::parse(in);
    in.close();
    j["source"]["label"] = 127;
    std::ofstream(dir / "model.json") << j.dump(2);
    expect_input_error(dir, "model.json of");
    expect_input_error(dir, "was altered");
  }
  {  // a truncated manifest
    const fs::path dir = fresh("manifest-truncated");
    auto b = read_all(dir / "model.json");
    b.resize(b.size() / 2);
    write_all(dir / "model.json", b);
    expect_input_error(dir, "not valid JSON");
  }
  {  // a newer manifest version
    const fs::path dir = fresh("newer");
    rewrite_manifest(dir, [](nlohmann::json& j) { j["format_version"] = kModelFormatVersion + 1; });
    expect_input_error(dir, "newer than this mrsnake reads");
  }
  {  // a newer binary version, with every checksum made consistent
    const fs::path dir = fresh("newer-binary");
    auto b = read_all(dir / "details.bin");
    b[8] = 2;
    const std::uint64_t sum = fnv1a64(b.data(), b.size() - 8);
    for (int i = 0; i < 8; ++i) b[b.size() - 8 + i] = static_cast<std::uint8_t>(sum >> (8 * i));
    write_all(dir / "details.bin", b);
    rewrite_manifest(dir,
                     [&](nlohmann::json& j) { j["files"]["details"]["fnv1a64"] = hex(fnv1a64(b.data(), b.size())); });
    expect_input_error(dir, "details.bin' of model");
    expect_input_error(dir, "has format version 2, newer");
  }
  {  // missing parts
    const fs::path dir = fresh("missing");
    fs::remove(dir / "level_1.vtp");
    expect_input_error(dir, "is missing its part 'level_1.vtp'");
    fs::remove(dir / "appearance.bin");
    fs::remove(dir / "model.json");
    expect_input_error(dir, "has no model.json");
    expect_input_error(root / "nowhere", "does not exist");
  }
  {  // a manifest that disagrees with the binary part
    const fs::path dir = fresh("disagree");
    rewrite_manifest(dir, [](nlohmann::json& j) { j["wavelet"]["predict"] = "linear"; });
    expect_input_error(dir, "disagree");
  }
  {  // a manifest field of the wrong type
    const fs::path dir = fresh("malformed");
    rewrite_manifest(dir, [](nlohmann::json& j) { j["levels"] = "three"; });
    expect_input_error(dir, "missing or malformed field");
  }
  {  // a file name that leaves the folder
    const fs::path dir = fresh("escape");
    rewrite_manifest(dir, [](nlohmann::json& j) { j["files"]["details"]["path"] = "../details.bin"; });
    expect_input_error(dir, "invalid file name");
  }
}

TEST(ModelInfoCli, PrintsTheManifestAndTheSynthesisError) {
  const fs::path root = scratch_dir("model-info-cli");
  const fs::path dir = root / "sphere.model";
  // model-info decodes the appearance section (tests/wavelets/test_build_model_cli.cpp); the
  // sample's bytes only stand in for one in the format tests.
  ShapeModel model = sample_model();
  model.sections.erase("appearance");
  save_model(dir.string(), model);
  const auto text = run_mrsnake("model-info " + dir.string());
  EXPECT_EQ(text.exit_code, 0) << text.output;
  EXPECT_NE(text.output.find("format version 1"), std::string::npos) << text.output;
  EXPECT_NE(text.output.find(": ok"), std::string::npos) << text.output;
  const auto json = run_mrsnake("model-info --json " + dir.string());
  ASSERT_EQ(json.exit_code, 0) << json.output;
  const nlohmann::json j = nlohmann::json::parse(json.output);
  EXPECT_EQ(j["manifest"]["levels"], 3);
  EXPECT_TRUE(j["synthesis"]["ok"].get<bool>());
  EXPECT_LE(j["synthesis"]["max_error_relative_to_diagonal"].get<double>(), 1e-9);

  auto b = read_all(dir / "details.bin");
  b.resize(b.size() - 1);
  write_all(dir / "details.bin", b);
  const auto bad = run_mrsnake("model-info " + dir.string());
  EXPECT_EQ(bad.exit_code, 3) << bad.output;
  EXPECT_NE(bad.output.find("truncated"), std::string::npos) << bad.output;
  // A damaged appearance section is the model's defect, named as such.
  const fs::path damaged = root / "damaged.model";
  save_model(damaged.string(), sample_model());
  const auto bad_appearance = run_mrsnake("model-info " + damaged.string());
  EXPECT_EQ(bad_appearance.exit_code, 3) << bad_appearance.output;
  EXPECT_NE(bad_appearance.output.find("appearance section"), std::string::npos) << bad_appearance.output;
  EXPECT_EQ(run_mrsnake("model-info " + (root / "absent.model").string()).exit_code, 3);
  EXPECT_EQ(run_mrsnake("model-info").exit_code, 2);
}
