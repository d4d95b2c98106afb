// Bad inputs, end to end through the mrsnake command: each test is one row of
// docs/robustness.md. Every case must give a one-line error with a non-zero exit code (or
// a documented, sane result), never a crash, and never an output under its final name.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <set>
#include <string>

#include <nlohmann/json.hpp>
#include <zlib.h>

#include "mesh/image_io.h"
#include "tests/test_support.h"

using mrsnake::test::run_mrsnake;
namespace fs = std::filesystem;

namespace {

/// One line of output that names the problem (no stack traces, no VTK/ITK dumps).
void expect_one_line_error(const mrsnake::test::CommandResult& r, int code, const std::string& needle) {
  EXPECT_EQ(r.exit_code, code) << r.output;
  EXPECT_NE(r.output.find("mrsnake: error: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(needle), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("itk::"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("ITK ERROR"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("(0x"), std::string::npos) << r.output;
}

/// A NIfTI-1 file with the given dimensions (uint8 voxels), written by hand so that 2D and
/// 4D images can be made.
void write_nifti(const fs::path& path, const std::vector<short>& dims) {
  char header[352] = {};
  const int sizeof_hdr = 348;
  std::memcpy(header, &sizeof_hdr, 4);
  short dim[8] = {static_cast<short>(dims.size()), 1, 1, 1, 1, 1, 1, 1};
  std::size_t voxels = 1;
  for (std::size_t i = 0; i < dims.size(); ++i) {
    dim[i + 1] = dims[i];
    voxels *= static_cast<std::size_t>(dims[i]);
  }
  std::memcpy(header + 40, dim, sizeof dim);
  const short datatype = 2, bitpix = 8;  // unsigned char
  std::memcpy(header + 70, &datatype, 2);
  std::memcpy(header + 72, &bitpix, 2);
  float pixdim[8] = {1, 1, 1, 1, 1, 1, 1, 1};
  std::memcpy(header + 76, pixdim, sizeof pixdim);
  const float vox_offset = 352;
  std::memcpy(header + 108, &vox_offset, 4);
  std::memcpy(header + 344, "n+1\0", 4);
  std::ofstream f(path, std::ios::binary);
  f.write(header, sizeof header);
  const std::vector<char> data(voxels, 1);
  f.write(data.data(), static_cast<std::streamsize>(data.size()));
}

int count_entries(const fs::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace

/// One small synthetic case and a model built from another instance, shared by the tests.
class Robustness : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(mrsnake::test::scratch_dir("robustness"));
    const std::string d = dir_->string();
    for (const auto& [name, seed] : {std::pair<std::string, int>{"ref", 5}, {"tgt", 6}}) {
      const auto r = run_mrsnake("-q synth --shape ellipsoid --size 48 --snr 6 --pose random --seed " +
                                 std::to_string(seed) + " -o " + d + "/" + name);
      ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    const auto b = run_mrsnake("-q build-model --labels " + d + "/ref/truth.nii.gz --label 1 -o " + d +
                               "/ellipsoid.model --faces 4000");
    ASSERT_EQ(b.exit_code, 0) << b.output;
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete dir_;
  }
  static std::string path(const std::string& name) { return (*dir_ / name).string(); }
  static fs::path* dir_;
};
fs::path* Robustness::dir_ = nullptr;

TEST_F(Robustness, CorruptImage) {
  std::ofstream(path("corrupt.nii.gz"), std::ios::binary) << "this is not a NIfTI file at all";
  expect_one_line_error(run_mrsnake("mc --labels " + path("corrupt.nii.gz") + " --label 1 -o " + path("c.vtp")), 3,
                        "corrupt.nii.gz");
  EXPECT_FALSE(fs::exists(path("c.vtp")));
}

TEST_F(Robustness, TruncatedImage) {
  std::ifstream in(path("tgt/image.nii.gz"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(path("truncated.nii.gz"), std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  expect_one_line_error(run_mrsnake("segment --image " + path("truncated.nii.gz") + " --model " +
                                    path("ellipsoid.model") + " -o " + path("seg-trunc")),
                        3, "truncated.nii.gz");
  EXPECT_FALSE(fs::exists(path("seg-trunc")));
}

TEST_F(Robustness, TwoDimensionalAndFourDimensionalImages) {
  write_nifti(path("flat.nii"), {32, 32});
  expect_one_line_error(run_mrsnake("mc --labels " + path("flat.nii") + " --label 1 -o " + path("f.vtp")), 3,
                        "2D image");
  write_nifti(path("series.nii"), {16, 16, 16, 3});
  expect_one_line_error(run_mrsnake("mc --labels " + path("series.nii") + " --label 1 -o " + path("s.vtp")), 3,
                        "4D image");
  // A 3D image stored with a trailing singleton dimension is a 3D image.
  write_nifti(path("single.nii"), {16, 16, 16, 1});
  EXPECT_EQ(run_mrsnake("mc --labels " + path("single.nii") + " --label 1 -o " + path("one.vtp")).exit_code, 0);
}

TEST_F(Robustness, EmptyLabelVolume) {
  mrsnake::Volume empty;
  empty.size = {20, 20, 20};
  empty.data.assign(empty.num_voxels(), 0.f);
  mrsnake::write_volume(path("empty.nii.gz"), empty, mrsnake::VoxelType::uint8);
  expect_one_line_error(
      run_mrsnake("build-model --labels " + path("empty.nii.gz") + " --label 1 -o " + path("e.model")), 3,
      "not present");
  EXPECT_FALSE(fs::exists(path("e.model")));
}

TEST_F(Robustness, MetaImageWithItsVoxelsInAnotherFile) {
  // .mhd and .nhdr headers name their voxel file (raw, or compressed: .zraw as VTK's frog
  // data, gzip-encoded NRRD); the size check must look at that file, not at the header, and
  // leave compressed voxels to zlib.
  std::vector<unsigned char> voxels(20 * 20 * 20, 0);
  for (int k = 0; k < 20; ++k)
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 20; ++i)
        if ((i - 9.5) * (i - 9.5) + (j - 9.5) * (j - 9.5) + (k - 9.5) * (k - 9.5) <= 36)
          voxels[i + 20 * (j + 20 * k)] = 1;
  const auto write_header = [&](const std::string& name, const std::string& data_file, std::size_t compressed_bytes) {
    std::ofstream h(path(name));
    h << "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n";
    if (compressed_bytes > 0) h << "CompressedData = True\nCompressedDataSize = " << compressed_bytes << "\n";
    h << "ElementSpacing = 1 1 1.5\nDimSize = 20 20 20\nElementType = MET_UCHAR\nElementDataFile = " << data_file
      << "\n";
  };
  const auto write_bytes = [&](const std::string& name, const unsigned char* data, std::size_t n) {
    std::ofstream(path(name), std::ios::binary)
        .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(n));
  };
  write_bytes("ball.raw", voxels.data(), voxels.size());
  write_header("ball.mhd", "ball.raw", 0);
  std::vector<unsigned char> packed(compressBound(voxels.size()));
  uLongf packed_size = packed.size();
  ASSERT_EQ(compress2(packed.data(), &packed_size, voxels.data(), voxels.size(), 6), Z_OK);
  write_bytes("ball.zraw", packed.data(), packed_size);
  write_header("ballz.mhd", "ball.zraw", packed_size);
  for (const std::string name : {"ball", "ballz"}) {
    const auto r = run_mrsnake("-q mc --labels " + path(name + ".mhd") + " --label 1 -o " + path(name + ".vtp"));
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.output;
  }
  write_bytes("short.raw", voxels.data(), voxels.size() / 2);
  write_header("short.mhd", "short.raw", 0);
  expect_one_line_error(run_mrsnake("mc --labels " + path("short.mhd") + " --label 1 -o " + path("s.vtp")), 3,
                        "short.raw' is truncated");
  write_header("orphan.mhd", "gone.raw", 0);
  expect_one_line_error(run_mrsnake("mc --labels " + path("orphan.mhd") + " --label 1 -o " + path("o.vtp")), 3,
                        "gone.raw', which is missing");
  write_header("orphanz.mhd", "gone.zraw", packed_size);
  expect_one_line_error(run_mrsnake("mc --labels " + path("orphanz.mhd") + " --label 1 -o " + path("o.vtp")), 3,
                        "gone.zraw', which is missing");
  EXPECT_FALSE(fs::exists(path("s.vtp")));
  EXPECT_FALSE(fs::exists(path("o.vtp")));

  // A damaged NRRD header: ITK's multi-line reason in one line, without ITK's prefix.
  std::ofstream(path("bad.nrrd")) << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 20 20\nencoding: raw\n\nxx";
  expect_one_line_error(run_mrsnake("mc --labels " + path("bad.nrrd") + " --label 1 -o " + path("b.vtp")), 3,
                        "parsed 2 values, but dimension is 3");

  // The same for NRRD: a detached header (.nhdr) naming its raw file, and gzip encoding.
  const auto write_nhdr = [&](const std::string& name, const std::string& data_file) {
    std::ofstream(path(name)) << "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 20 20 20\nspacings: 1 1 1.5\n"
                                 "encoding: raw\ndata file: "
                              << data_file << "\n\n";
  };
  write_nhdr("ball.nhdr", "ball.raw");
  const auto nhdr = run_mrsnake("-q mc --labels " + path("ball.nhdr") + " --label 1 -o " + path("nhdr.vtp"));
  EXPECT_EQ(nhdr.exit_code, 0) << nhdr.output;
  write_nhdr("short.nhdr", "short.raw");
  expect_one_line_error(run_mrsnake("mc --labels " + path("short.nhdr") + " --label 1 -o " + path("sn.vtp")), 3,
                        "short.raw' is truncated");
  write_nhdr("orphan.nhdr", "gone.raw");
  expect_one_line_error(run_mrsnake("mc --labels " + path("orphan.nhdr") + " --label 1 -o " + path("on.vtp")), 3,
                        "gone.raw");
  mrsnake::Volume ball;
  ball.size = {20, 20, 20};
  ball.data.assign(voxels.begin(), voxels.end());
  mrsnake::write_volume(path("ball.nrrd"), ball, mrsnake::VoxelType::uint8);  // gzip-encoded
  std::ifstream written(path("ball.nrrd"), std::ios::binary);
  const std::string nrrd((std::istreambuf_iterator<char>(written)), std::istreambuf_iterator<char>());
  ASSERT_NE(nrrd.find("encoding: gzip"), std::string::npos);
  ASSERT_LT(nrrd.size(), voxels.size());  // smaller than its voxels: a size check would refuse it
  const auto gz = run_mrsnake("-q mc --labels " + path("ball.nrrd") + " --label 1 -o " + path("nrrd.vtp"));
  EXPECT_EQ(gz.exit_code, 0) << gz.output;
}

TEST_F(Robustness, NanAndInfVoxelsAreIgnored) {
  mrsnake::Volume image = mrsnake::read_volume(path("tgt/image.nii.gz"));
  for (std::size_t i = 0; i < image.data.size(); i += 97) image.data[i] = std::numeric_limits<float>::quiet_NaN();
  for (std::size_t i = 13; i < image.data.size(); i += 101) image.data[i] = std::numeric_limits<float>::infinity();
  mrsnake::write_volume(path("nan.nii.gz"), image, mrsnake::VoxelType::float32);
  const auto r = run_mrsnake("-q segment --image " + path("nan.nii.gz") + " --model " + path("ellipsoid.model") +
                             " -o " + path("seg-nan") + " --truth " + path("tgt/truth.nii.gz") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto report = nlohmann::json::parse(r.output);
  EXPECT_GE(report["scores"]["dice"].get<double>(), 0.9) << "1% of the voxels are NaN or Inf";
  EXPECT_EQ(report["self_intersections"], 0);
}

TEST_F(Robustness, ExtremeAnisotropy) {
  const auto s = run_mrsnake("-q synth --shape ellipsoid --size 96,96,12 --spacing 0.4,0.4,5 --snr 6 --seed 9 -o " +
                             path("aniso"));
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const auto r =
      run_mrsnake("-q segment --image " + path("aniso/image.nii.gz") + " --model " + path("ellipsoid.model") + " -o " +
                  path("seg-aniso") + " --truth " + path("aniso/truth.nii.gz") + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto report = nlohmann::json::parse(r.output);
  EXPECT_EQ(report["self_intersections"], 0);
  EXPECT_GE(report["scores"]["dice"].get<double>(), 0.8) << "5 mm slices, 0.4 mm in plane";
  const mrsnake::Volume labels = mrsnake::read_volume(path("seg-aniso/labels.nii.gz"));
  EXPECT_EQ(labels.size, (std::array<std::size_t, 3>{96, 96, 12}));
  EXPECT_DOUBLE_EQ(labels.spacing[2], 5.0);
}

TEST_F(Robustness, UnwritableOutput) {
  std::ofstream(path("a-file")) << "x";
  expect_one_line_error(run_mrsnake("segment --image " + path("tgt/image.nii.gz") + " --model " +
                                    path("ellipsoid.model") + " -o " + path("a-file/seg")),
                        4, "a-file");
}

// Whether process `pid`, once it runs mrsnake (its Name in /proc), catches `sig` (its SigCgt
// mask), waiting up to 30 s for it.
bool wait_for_handler(pid_t pid, int sig) {
  for (int tries = 0; tries < 600; ++tries) {
    std::ifstream status("/proc/" + std::to_string(pid) + "/status");
    bool mrsnake = false, catches = false;
    for (std::string line; std::getline(status, line);) {
      if (line.rfind("Name:", 0) == 0) mrsnake = line.find("mrsnake") != std::string::npos;
      if (line.rfind("SigCgt:", 0) == 0) catches = std::stoull(line.substr(7), nullptr, 16) >> (sig - 1) & 1ULL;
    }
    if (mrsnake && catches) return true;
    usleep(50000);
  }
  return false;
}

TEST_F(Robustness, InterruptLeavesNoPartialOutput) {
  const fs::path out = *dir_ / "interrupted";
  fs::create_directories(out);
  const char* bin = std::getenv("MRSNAKE_BIN");
  ASSERT_NE(bin, nullptr);
  for (int sig : {SIGINT, SIGTERM}) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      const std::string model = (out / "big.model").string();
      execl(bin, bin, "-q", "build-model", "--labels", path("ref/truth.nii.gz").c_str(), "--label", "1", "-o",
            model.c_str(), "--faces", "130000", static_cast<char*>(nullptr));
      _exit(127);
    }
    // Interrupt it mid-way, once its handlers are in place: under the sanitizers and a loaded
    // machine, starting up alone can take longer than a fixed wait.
    ASSERT_TRUE(wait_for_handler(child, sig)) << "the command never installed its signal handler";
    usleep(300000);  // build-model at 130k faces takes several seconds
    kill(child, sig);
    int status = 0;
    waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal instead of exiting cleanly";
    EXPECT_EQ(WEXITSTATUS(status), 128 + sig) << "it finished before the interrupt; make the job bigger";
    EXPECT_EQ(count_entries(out), 0) << "a partial output or temporary survived";
  }
}

TEST_F(Robustness, BatchGoesOnPastABadImageAndSummarizesEveryImage) {
  // Three images, one of them corrupt, two of them named image.nii.gz; the third given in a list.
  std::ofstream(path("bad.nii.gz"), std::ios::binary) << "this is not a NIfTI file at all";
  std::ofstream(path("list.txt")) << "# one more\n\nref/image.nii.gz\n";
  const std::string out = path("batch");
  const auto r = run_mrsnake("segment-batch --model " + path("ellipsoid.model") + " -o " + out + " " +
                             path("tgt/image.nii.gz") + " " + path("bad.nii.gz") + " --list " + path("list.txt"));
  EXPECT_EQ(r.exit_code, 6) << r.output;
  EXPECT_NE(r.output.find("mrsnake: error: 1 of 3 images failed; each is listed with its error in "), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("[2/3] bad failed: "), std::string::npos) << r.output;

  const auto summary = nlohmann::json::parse(mrsnake::test::read_all(fs::path(out) / "batch.json"));
  ASSERT_EQ(summary["cases"].size(), 3u);
  EXPECT_EQ(summary["succeeded"], 2);
  EXPECT_EQ(summary["failed"], 1);
  const auto& bad = summary["cases"][1];
  EXPECT_EQ(bad["status"], "failed");
  EXPECT_EQ(bad["exit_code"], 3);
  EXPECT_NE(bad["error"].get<std::string>().find("bad.nii.gz"), std::string::npos);
  EXPECT_FALSE(fs::exists(fs::path(out) / "bad"));
  // The two named image.nii.gz get their folders' names; each folder is what segment writes.
  for (const auto& [index, name] : {std::pair<int, std::string>{0, "tgt_image"}, {2, "ref_image"}}) {
    const auto& c = summary["cases"][index];
    EXPECT_EQ(c["status"], "ok") << c.dump();
    EXPECT_EQ(c["output"], (fs::path(out) / name).string());
    EXPECT_EQ(c["self_intersections"], 0);
    for (const char* file : {"surface.vtp", "labels.nii.gz", "report.json", "report.html", "levels/level_0.vtp"})
      EXPECT_TRUE(fs::exists(fs::path(out) / name / file)) << name << "/" << file;
  }
  // The same labels as a single segment, and the volume they hold, near the truth's.
  const auto single = run_mrsnake("-q segment --image " + path("tgt/image.nii.gz") + " --model " +
                                  path("ellipsoid.model") + " -o " + path("single") + " --json");
  ASSERT_EQ(single.exit_code, 0) << single.output;
  const mrsnake::Volume batch_labels = mrsnake::read_volume(out + "/tgt_image/labels.nii.gz");
  EXPECT_EQ(batch_labels.data, mrsnake::read_volume(path("single/labels.nii.gz")).data);
  const mrsnake::Volume truth = mrsnake::read_volume(path("tgt/truth.nii.gz"));
  const double voxel = truth.spacing[0] * truth.spacing[1] * truth.spacing[2];
  const double truth_mm3 = voxel * static_cast<double>(std::count(truth.data.begin(), truth.data.end(), 1.0f));
  const double volume = summary["cases"][0]["volume_mm3"].get<double>();
  EXPECT_DOUBLE_EQ(volume, nlohmann::json::parse(single.output)["volume_mm3"].get<double>());
  EXPECT_NEAR(volume / truth_mm3, 1.0, 0.05);
  // batch.csv: a header and a row per image, the error quoted.
  std::ifstream csv(fs::path(out) / "batch.csv");
  std::vector<std::string> lines;
  for (std::string line; std::getline(csv, line);) lines.push_back(line);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0].rfind("image,output,status,volume_mm3,", 0), 0u) << lines[0];
  EXPECT_NE(lines[2].find(",failed,"), std::string::npos) << lines[2];
  EXPECT_NE(lines[1].find(",ok,"), std::string::npos) << lines[1];
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".tmp"), std::string::npos) << e.path();

  // Two worker processes: the same rows (in the order given) and the same labels.
  const auto two =
      run_mrsnake("-q segment-batch --jobs 2 --model " + path("ellipsoid.model") + " -o " + path("batch2") + " " +
                  path("tgt/image.nii.gz") + " " + path("bad.nii.gz") + " --list " + path("list.txt"));
  EXPECT_EQ(two.exit_code, 6) << two.output;
  const auto summary2 = nlohmann::json::parse(mrsnake::test::read_all(fs::path(path("batch2")) / "batch.json"));
  ASSERT_EQ(summary2["cases"].size(), 3u);
  EXPECT_EQ(summary2["jobs"], 2);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(summary2["cases"][i]["status"], summary["cases"][i]["status"]) << i;
    EXPECT_EQ(summary2["cases"][i].value("volume_mm3", -1.0), summary["cases"][i].value("volume_mm3", -1.0)) << i;
  }
  EXPECT_EQ(mrsnake::read_volume(path("batch2/ref_image/labels.nii.gz")).data,
            mrsnake::read_volume(out + "/ref_image/labels.nii.gz").data);

  // Nothing to segment is a usage error.
  EXPECT_EQ(run_mrsnake("segment-batch --model " + path("ellipsoid.model") + " -o " + path("batch-none")).exit_code, 2);
}

TEST_F(Robustness, BatchResumeKeepsOnlyCompleteResultsOfTheSameInputs) {
  // Two images, one of them a MetaImage whose voxels sit in a file of their own.
  const fs::path in = *dir_ / "resume-in";
  fs::create_directories(in);
  fs::copy_file(path("tgt/image.nii.gz"), in / "a.nii.gz");
  {
    const mrsnake::Volume ref = mrsnake::read_volume(path("ref/image.nii.gz"));
    std::ofstream(in / "b.mhd") << "ObjectType = Image\nNDims = 3\nDimSize = " << ref.size[0] << " " << ref.size[1]
                                << " " << ref.size[2] << "\nElementSpacing = " << ref.spacing[0] << " "
                                << ref.spacing[1] << " " << ref.spacing[2]
                                << "\nElementType = MET_FLOAT\nElementByteOrderMSB = False\nElementDataFile = b.raw\n";
    std::ofstream(in / "b.raw", std::ios::binary)
        .write(reinterpret_cast<const char*>(ref.data.data()), static_cast<std::streamsize>(ref.data.size() * 4));
  }
  const std::string out = path("resume-out");
  const std::string batch = "-q segment-batch --model " + path("ellipsoid.model") + " -o " + out + " " +
                            (in / "a.nii.gz").string() + " " + (in / "b.mhd").string();
  const auto run = [&](const std::string& extra) {
    const auto r = run_mrsnake(batch + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    const auto summary = nlohmann::json::parse(mrsnake::test::read_all(fs::path(out) / "batch.json"));
    std::vector<bool> resumed;
    for (const auto& c : summary["cases"]) resumed.push_back(c["resumed"].get<bool>());
    return resumed;
  };
  EXPECT_EQ(run(""), (std::vector<bool>{false, false}));
  const auto report_a = nlohmann::json::parse(mrsnake::test::read_all(fs::path(out) / "a" / "report.json"));
  for (const char* key : {"image_fnv1a64", "model_fnv1a64", "options_fnv1a64"})
    EXPECT_EQ(report_a["fingerprint"][key].get<std::string>().size(), 16u) << key;
  EXPECT_TRUE(fs::is_regular_file(fs::path(out) / "a" / "slices.png"));

  // Nothing changed: both kept, their files untouched.
  const auto written = fs::last_write_time(fs::path(out) / "a" / "labels.nii.gz");
  EXPECT_EQ(run(" --resume"), (std::vector<bool>{true, true}));
  EXPECT_EQ(fs::last_write_time(fs::path(out) / "a" / "labels.nii.gz"), written);
  // Without --resume every image is segmented again.
  EXPECT_EQ(run(""), (std::vector<bool>{false, false}));

  // The MetaImage's voxels change (its header does not): only b is redone.
  {
    std::fstream raw(in / "b.raw", std::ios::in | std::ios::out | std::ios::binary);
    ASSERT_TRUE(raw.good());
    const float v = 123.f;
    raw.seekp(4 * 100);
    raw.write(reinterpret_cast<const char*>(&v), sizeof v);
  }
  EXPECT_EQ(run(" --resume"), (std::vector<bool>{true, false}));
  // An incomplete result is redone; other options redo every image.
  fs::remove(fs::path(out) / "a" / "surfaces" / "1.vtp");
  EXPECT_EQ(run(" --resume"), (std::vector<bool>{false, true}));
  EXPECT_EQ(run(" --resume --max-iterations 7"), (std::vector<bool>{false, false}));
  std::ifstream csv(fs::path(out) / "batch.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find(",error,resumed"), std::string::npos) << header;
}

TEST_F(Robustness, BatchNamesAreDistinctAndNeverReplaceOtherData) {
  // Copies of one image under names that collide, that are the summary's own, that are
  // hidden, that are not UTF-8 (byte 0xFF), and one named like a folder of other data in -o.
  const fs::path in = *dir_ / "names";
  fs::create_directories(in / "d");
  fs::create_directories(in / ".cache");
  const std::vector<std::string> files{"x.nii.gz",       "d/x_2.nii.gz",    "batch.json.nii.gz", "..nii.gz",
                                       "bad\xff.nii.gz", "precious.nii.gz", ".cache/x_2.nii.gz"};
  for (const std::string& f : files) fs::copy_file(path("tgt/image.nii.gz"), in / f);
  const fs::path out = *dir_ / "names-out";
  fs::create_directories(out / "precious");
  std::ofstream(out / "precious" / "notes.txt") << "not mrsnake's";
  std::string args = "-q segment-batch --jobs 2 --model " + path("ellipsoid.model") + " -o " + out.string();
  for (const std::string& f : files) args += " '" + (in / f).string() + "'";
  args += " '" + (in / "x.nii.gz").string() + "'";  // the same image twice
  const auto r = run_mrsnake(args);
  EXPECT_EQ(r.exit_code, 6) << r.output;
  const auto summary = nlohmann::json::parse(mrsnake::test::read_all(out / "batch.json"));
  ASSERT_EQ(summary["cases"].size(), files.size() + 1);
  std::set<std::string> outputs;
  for (const auto& c : summary["cases"]) {
    const std::string name = fs::path(c["output"].get<std::string>()).filename().string();
    EXPECT_TRUE(outputs.insert(name).second) << "two images share " << name;
    EXPECT_NE(name.front(), '.') << name;
    EXPECT_TRUE(name != "batch.json" && name != "batch.csv") << name;
    if (name == "precious") {
      EXPECT_EQ(c["status"], "failed");
      EXPECT_NE(c["error"].get<std::string>().find("exists and is not an output of mrsnake segment"),
                std::string::npos);
    } else {
      EXPECT_EQ(c["status"], "ok") << name << ": " << c.dump();
    }
  }
  EXPECT_TRUE(fs::is_regular_file(out / "batch.json"));
  // batch.csv keeps the path's bytes as given, from a worker process too.
  const auto csv = mrsnake::test::read_all(out / "batch.csv");
  EXPECT_NE(std::string(csv.begin(), csv.end()).find("bad\xff.nii.gz"), std::string::npos);
  EXPECT_TRUE(fs::exists(out / "precious" / "notes.txt")) << "another program's folder was replaced";
  // A report.json beside other files does not make a folder an earlier result.
  std::ofstream(out / "precious" / "report.json") << "{}";
  EXPECT_EQ(run_mrsnake("-q segment --image " + path("tgt/image.nii.gz") + " --model " + path("ellipsoid.model") +
                        " -o " + (out / "precious").string())
                .exit_code,
            4);
  fs::remove(out / "precious" / "report.json");
  // Nor does remesh replace other data.
  expect_one_line_error(
      run_mrsnake("remesh " + path("ref/truth.vtp") + " --faces 512 -o " + (out / "precious").string()), 4,
      "exists and is not an output of mrsnake remesh");
  // The single command refuses such a folder too, and replaces an earlier result.
  const auto single = run_mrsnake("segment --image " + path("tgt/image.nii.gz") + " --model " +
                                  path("ellipsoid.model") + " -o " + (out / "precious").string());
  expect_one_line_error(single, 4, "exists and is not an output of mrsnake segment");
  EXPECT_TRUE(fs::exists(out / "precious" / "notes.txt"));
  EXPECT_EQ(run_mrsnake("-q segment --image " + path("tgt/image.nii.gz") + " --model " + path("ellipsoid.model") +
                        " -o " + (out / "x").string())
                .exit_code,
            0);
}

TEST_F(Robustness, InterruptedBatchLeavesNoPartialOutputNorWorkers) {
  // segment-batch --jobs 2 on 80 images (about 0.1 s each), killed mid-way (SIGTERM to the batch alone): its
  // workers must die with it, each removing its own temporaries.
  const fs::path out = *dir_ / "batch-interrupted";
  {
    std::ofstream list(path("eighty.txt"));
    for (int i = 0; i < 80; ++i) list << path("tgt/image.nii.gz") << "\n";
  }
  const char* bin = std::getenv("MRSNAKE_BIN");
  ASSERT_NE(bin, nullptr);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    execl(bin, bin, "-q", "segment-batch", "--jobs", "2", "--model", path("ellipsoid.model").c_str(), "-o", out.c_str(),
          "--list", path("eighty.txt").c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Killed once the first image is done (batch.json written): the workers are then inside
  // their next images, whatever the speed of the machine (or of a sanitizer build).
  for (int wait = 0; wait < 3000 && !fs::exists(out / "batch.json"); ++wait) usleep(20000);
  kill(child, SIGTERM);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by a signal instead of exiting cleanly";
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << "it finished before the interrupt; make the batch bigger";
  // The workers: gone within a moment (their command line names the output folder).
  const auto workers_alive = [&] {
    int alive = 0;
    for (const auto& e : fs::directory_iterator("/proc")) {
      std::ifstream cmdline(e.path() / "cmdline", std::ios::binary);
      const std::string text((std::istreambuf_iterator<char>(cmdline)), std::istreambuf_iterator<char>());
      alive += text.find(out.string()) != std::string::npos;
    }
    return alive;
  };
  for (int wait = 0; wait < 50 && workers_alive() > 0; ++wait) usleep(100000);
  EXPECT_EQ(workers_alive(), 0);
  // Some images were done before the kill (so the workers ran), and their record is whole.
  const auto summary = nlohmann::json::parse(mrsnake::test::read_all(out / "batch.json"));
  EXPECT_GE(summary["cases"].size(), 1u);
  EXPECT_LT(summary["cases"].size(), 80u);
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp", 0), std::string::npos) << "a temporary survived: " << e.path();
}

TEST_F(Robustness, TruncatedUncompressedImage) {
  write_nifti(path("full.nii"), {16, 16, 16});
  std::ifstream in(path("full.nii"), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(path("short.nii"), std::ios::binary) << bytes.substr(0, 352 + 1000);
  expect_one_line_error(run_mrsnake("mc --labels " + path("short.nii") + " --label 1 -o " + path("t.vtp")), 3,
                        "truncated");
}

TEST(CommandLine, NonFiniteNumbersAreUsageErrors) {
  // CLI11's ranges let nan through (every comparison with it is false); every FLOAT option of
  // every command must refuse nan and inf with a one-line usage error (exit 2) naming the option.
  const std::string out = mrsnake::test::scratch_dir("non-finite").string();
  for (const std::string& args :
       {"synth -o " + out + "/s --snr inf", "synth -o " + out + "/s --blur -inf", "synth -o " + out + "/s --snr nan"}) {
    const auto r = run_mrsnake(args);
    EXPECT_EQ(r.exit_code, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find("needs a finite number"), std::string::npos) << args << "\n" << r.output;
    EXPECT_EQ(r.output.find("internal error"), std::string::npos) << args << "\n" << r.output;
  }
  EXPECT_TRUE(fs::is_empty(out));
}

TEST(CommandLine, ANegativeIterationCountIsAUsageError) {
  // Unset, the count is the options' own; 0 writes the placed model; below that is a mistake.
  for (const std::string count : {"-3", "-1"}) {
    const auto r = run_mrsnake("segment --model m --image i.nii.gz -o o --max-iterations " + count);
    EXPECT_EQ(r.exit_code, 2) << count << "\n" << r.output;
    EXPECT_NE(r.output.find("--max-iterations"), std::string::npos) << count << "\n" << r.output;
  }
}
