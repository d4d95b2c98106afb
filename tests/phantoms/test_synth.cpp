// Synthetic cases: exact truth, partial volume, noise, pose, deformation, reproducibility.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/image_io.h"
#include "mesh/marching_cubes.h"
#include "mesh/mesh_io.h"
#include "mesh/topology.h"
#include "evaluation/evaluate.h"
#include "phantoms/synth.h"
#include "tests/test_support.h"

namespace mrsnake {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Trilinear interpolation at a physical point (0 outside the grid).
double trilinear(const Volume& v, const Eigen::Vector3d& p) {
  const auto x = v.physical_to_index({p.x(), p.y(), p.z()});
  const double fi = std::floor(x[0]), fj = std::floor(x[1]), fk = std::floor(x[2]);
  double sum = 0;
  for (int c = 0; c < 8; ++c) {
    const long i = long(fi) + (c & 1), j = long(fj) + ((c >> 1) & 1), k = long(fk) + ((c >> 2) & 1);
    const double w = (c & 1 ? x[0] - fi : 1 - (x[0] - fi)) * ((c >> 1) & 1 ? x[1] - fj : 1 - (x[1] - fj)) *
                     ((c >> 2) & 1 ? x[2] - fk : 1 - (x[2] - fk));
    if (i < 0 || j < 0 || k < 0 || i >= long(v.size[0]) || j >= long(v.size[1]) || k >= long(v.size[2])) continue;
    sum += w * v.at(i, j, k);
  }
  return sum;
}

Volume object_mask(const Volume& truth) {
  Volume m = truth;
  for (float& x : m.data) x = x == kTruthLabel ? 1.0f : 0.0f;
  return m;
}

Eigen::Vector3d unit_gradient(const SynthParams& p, const Eigen::Vector3d& x) {
  Eigen::Vector3d g;
  for (int d = 0; d < 3; ++d) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e[d] = 1e-4;
    g[d] = object_function(p, x + e) - object_function(p, x - e);
  }
  return g.normalized();
}

SynthOptions clean_options(SynthShape shape) {
  SynthOptions o;
  o.shape = shape;
  o.noise = SynthNoise::none;
  o.blur_mm = 0;
  return o;
}

// --- truth: label, mesh and image agree with the analytic shape ------------------------------

class SynthShapes : public ::testing::TestWithParam<SynthShape> {};

TEST_P(SynthShapes, TruthMeshLiesOnTheHalfLevelOfTheTruthVolume) {
  SynthOptions o = clean_options(GetParam());
  o.size = {56, 60, 48};
  o.spacing = {1.0, 0.9, 1.3};
  o.random_pose = true;
  o.deform_mm = 3;
  o.seed = 11;
  const SynthParams p = draw_synth_params(o);
  const SynthResult r = render_synth(p);
  const TopologyReport topo = topology_report(r.truth_mesh);
  EXPECT_TRUE(topo.is_closed_genus0()) << topo.describe();

  // Every vertex is on the analytic surface.
  double worst = 0;
  for (int v = 0; v < r.truth_mesh.num_vertices(); ++v)
    worst = std::max(worst, std::abs(object_function(p, r.truth_mesh.V.row(v).transpose())));
  EXPECT_LT(worst, 1e-6);

  // The truth label is the inside test of each voxel centre.
  std::size_t mismatches = 0, object_voxels = 0;
  for (std::size_t k = 0; k < r.truth.size[2]; ++k)
    for (std::size_t j = 0; j < r.truth.size[1]; ++j)
      for (std::size_t i = 0; i < r.truth.size[0]; ++i) {
        const auto c = r.truth.index_to_physical(i, j, k);
        const bool inside = object_function(p, {c[0], c[1], c[2]}) < 0;
        mismatches += inside != (r.truth.at(i, j, k) == kTruthLabel);
        object_voxels += inside;
      }
  EXPECT_EQ(mismatches, 0u);

  // Trilinear interpolation of the binary truth at the vertices averages 0.5; moved by half
  // a voxel along the normal, the same average is off by more than 0.25.
  const Volume mask = object_mask(r.truth);
  const double half_voxel = 0.5 * std::cbrt(o.spacing[0] * o.spacing[1] * o.spacing[2]);
  double on = 0, out = 0, in = 0;
  const int n = r.truth_mesh.num_vertices();
  for (int v = 0; v < n; ++v) {
    const Eigen::Vector3d x = r.truth_mesh.V.row(v).transpose();
    const Eigen::Vector3d normal = unit_gradient(p, x);
    on += trilinear(mask, x);
    out += trilinear(mask, x + half_voxel * normal);
    in += trilinear(mask, x - half_voxel * normal);
  }
  on /= n, out /= n, in /= n;
  std::cout << to_string(o.shape) << ": mean truth at the mesh " << on << ", half a voxel out " << out << ", in " << in
            << "; mesh volume " << enclosed_volume(r.truth_mesh) << " mm3, voxels "
            << object_voxels * o.spacing[0] * o.spacing[1] * o.spacing[2] << " mm3\n";
  EXPECT_NEAR(on, 0.5, 0.05);
  EXPECT_LT(out, 0.25);
  EXPECT_GT(in, 0.75);

  // The mesh encloses the volume of the label.
  const double voxel_mm3 = o.spacing[0] * o.spacing[1] * o.spacing[2];
  EXPECT_NEAR(enclosed_volume(r.truth_mesh) / (object_voxels * voxel_mm3), 1.0, 0.02);
}

INSTANTIATE_TEST_SUITE_P(AllShapes, SynthShapes,
                         ::testing::Values(SynthShape::sphere, SynthShape::ellipsoid, SynthShape::blob,
                                           SynthShape::aneurysm, SynthShape::heart),
                         [](const auto& info) { return to_string(info.param); });

TEST(Synth, PartialVolumeIntegratesToTheAnalyticVolume) {
  SynthOptions o = clean_options(SynthShape::sphere);
  o.spacing = {1.0, 1.0, 1.5};
  const SynthParams p = draw_synth_params(o);
  const SynthResult r = render_synth(p);
  double fraction_sum = 0;
  std::size_t voxels = 0;
  for (std::size_t i = 0; i < r.image.data.size(); ++i) {
    fraction_sum += (r.image.data[i] - o.background) / (o.foreground - o.background);
    voxels += r.truth.data[i] == kTruthLabel;
  }
  const double voxel_mm3 = 1.5;
  const double exact = 4.0 / 3.0 * kPi * std::pow(p.shape.radius, 3);
  const double pv = fraction_sum * voxel_mm3, counted = voxels * voxel_mm3;
  std::cout << "sphere r=" << p.shape.radius << " mm: exact " << exact << " mm3, partial volume " << pv
            << ", voxel count " << counted << "\n";
  EXPECT_NEAR(pv / exact, 1.0, 0.002);
  EXPECT_GT(std::abs(counted - exact), std::abs(pv - exact));  // the fractions beat plain counting
  // Pure voxels are exactly the two intensities.
  EXPECT_EQ(r.image.at(0, 0, 0), o.background);
  EXPECT_EQ(r.image.at(32, 32, 32), o.foreground);
}

TEST(Synth, HeartMarksCavityAndWall) {
  const SynthParams p = draw_synth_params(clean_options(SynthShape::heart));
  const SynthResult r = render_synth(p);
  std::size_t cavity = 0, wall = 0;
  for (float v : r.truth.data) cavity += v == kTruthLabel, wall += v == kWallLabel;
  EXPECT_GT(cavity, 1000u);
  EXPECT_GT(wall, cavity / 2);
  nlohmann::json j = p;
  EXPECT_EQ(j.at("label").get<int>(), 1);
  EXPECT_EQ(j.at("wall_label").get<int>(), 2);
}

TEST(Synth, ThresholdingTheImageRecoversTheTruth) {
  // End to end with evaluate: a blurred, noisy blob thresholded half-way between the two
  // intensities is close to its truth.
  SynthOptions o;
  o.shape = SynthShape::blob;
  o.blur_mm = 1.0;
  o.snr = 10;
  o.random_pose = true;
  o.deform_mm = 3;
  o.seed = 4;
  const SynthResult r = render_synth(draw_synth_params(o));
  Volume seg = r.image;
  for (float& v : seg.data) v = v > 0.5 * (o.foreground + o.background) ? 1.0f : 0.0f;
  const SegmentationScores s = evaluate_segmentation(seg, r.truth);
  std::cout << "threshold of a blob (blur 1 mm, snr 10): dice " << s.dice << ", volume difference "
            << s.volume_difference_pct << " %, assd " << s.assd_mm << " mm, hd95 " << s.hd95_mm << " mm, hausdorff "
            << s.hausdorff_mm << " mm\n";
  EXPECT_GT(s.dice, 0.97);
  EXPECT_LT(std::abs(s.volume_difference_pct), 3.0);
  EXPECT_LT(s.assd_mm, 0.5);
  EXPECT_LE(s.hd95_mm, 1.0);
}

// --- noise, bias and blur -------------------------------------------------------------------

TEST(Synth, GaussianNoiseHasTheRequestedSnr) {
  SynthOptions o = clean_options(SynthShape::sphere);
  const SynthResult clean = render_synth(draw_synth_params(o));
  o.noise = SynthNoise::gaussian;
  o.snr = 10;
  const SynthResult noisy = render_synth(draw_synth_params(o));
  double sum = 0, sum2 = 0;
  for (std::size_t i = 0; i < clean.image.data.size(); ++i) {
    const double d = noisy.image.data[i] - clean.image.data[i];
    sum += d, sum2 += d * d;
  }
  const double n = clean.image.data.size(), mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.1);
  EXPECT_NEAR(sd, (o.foreground - o.background) / o.snr, 0.02 * 15);
}

TEST(Synth, RicianNoiseIsRayleighWhereTheSignalIsZero) {
  SynthOptions o = clean_options(SynthShape::sphere);
  o.foreground = 100;
  o.background = 0;
  o.noise = SynthNoise::rician;
  o.snr = 4;  // sigma 25
  const SynthResult r = render_synth(draw_synth_params(o));
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < r.image.data.size(); ++i)
    if (r.truth.data[i] == 0 && i % 3 == 0) sum += r.image.data[i], ++n;  // mostly far from the sphere
  EXPECT_NEAR(sum / n, 25 * std::sqrt(kPi / 2), 0.02 * 25 * std::sqrt(kPi / 2));
  EXPECT_GE(*std::min_element(r.image.data.begin(), r.image.data.end()), 0.0f);
}

TEST(Synth, BiasFieldStaysWithinItsBounds) {
  SynthOptions o = clean_options(SynthShape::blob);
  const SynthResult clean = render_synth(draw_synth_params(o));
  o.bias = 0.4;
  const SynthResult biased = render_synth(draw_synth_params(o));
  double lo = 10, hi = 0;
  for (std::size_t i = 0; i < clean.image.data.size(); ++i) {
    const double ratio = biased.image.data[i] / clean.image.data[i];
    lo = std::min(lo, ratio), hi = std::max(hi, ratio);
  }
  EXPECT_GE(lo, std::exp(-0.4) - 1e-5);
  EXPECT_LE(hi, std::exp(0.4) + 1e-5);
  EXPECT_GT(hi / lo, 1.2);  // the field does vary
}

TEST(Synth, BlurKeepsTheTotalAndSoftensEdges) {
  SynthOptions o = clean_options(SynthShape::sphere);
  const SynthResult sharp = render_synth(draw_synth_params(o));
  o.blur_mm = 2.0;
  const SynthResult blurred = render_synth(draw_synth_params(o));
  double a = 0, b = 0;
  for (std::size_t i = 0; i < sharp.image.data.size(); ++i) a += sharp.image.data[i], b += blurred.image.data[i];
  EXPECT_NEAR(b / a, 1.0, 0.002);
  // Along the x axis through the centre, the edge spreads over more voxels.
  auto ramp = [](const Volume& v) {
    int count = 0;
    for (std::size_t i = 0; i < v.size[0]; ++i) {
      const float x = v.at(i, 32, 32);
      count += x > 60 && x < 190;
    }
    return count;
  };
  EXPECT_GE(ramp(blurred.image), ramp(sharp.image) + 4);
}

// --- pose and deformation -------------------------------------------------------------------

TEST(Synth, RandomPoseMovesTheSphereAsRecorded) {
  SynthOptions o = clean_options(SynthShape::sphere);
  o.random_pose = true;
  o.seed = 5;
  const SynthParams p = draw_synth_params(o);
  EXPECT_NEAR((p.pose.rotation * p.pose.rotation.transpose() - Eigen::Matrix3d::Identity()).norm(), 0, 1e-12);
  EXPECT_NEAR(p.pose.rotation.determinant(), 1, 1e-12);
  EXPECT_GE(p.pose.scale, 0.9);
  EXPECT_LE(p.pose.scale, 1.1);
  EXPECT_GT(p.pose.translation.norm(), 0.0);
  const SynthResult r = render_synth(p);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  std::size_t n = 0;
  for (std::size_t k = 0; k < r.truth.size[2]; ++k)
    for (std::size_t j = 0; j < r.truth.size[1]; ++j)
      for (std::size_t i = 0; i < r.truth.size[0]; ++i)
        if (r.truth.at(i, j, k) == kTruthLabel) {
          const auto c = r.truth.index_to_physical(i, j, k);
          sum += Eigen::Vector3d(c[0], c[1], c[2]);
          ++n;
        }
  EXPECT_LT((sum / n - p.pose.translation).norm(), 0.1);
  EXPECT_NEAR(n / (4.0 / 3.0 * kPi * std::pow(p.pose.scale * p.shape.radius, 3)), 1.0, 0.01);
}

TEST(Synth, DeformationHasTheRequestedAmplitudeAndRefusesFolding) {
  SynthOptions o = clean_options(SynthShape::blob);
  o.deform_mm = 4;
  const SynthParams p = draw_synth_params(o);
  double largest = 0;
  for (double x = -31.5; x <= 31.5; x += 3)
    for (double y = -31.5; y <= 31.5; y += 3)
      for (double z = -31.5; z <= 31.5; z += 3)
        largest = std::max(largest, p.deformation.displacement({x, y, z}).norm());
  EXPECT_NEAR(largest, 4.0, 0.4);
  // The analytic Jacobian matches finite differences.
  const Eigen::Vector3d x(3, -2, 5);
  Eigen::Matrix3d fd;
  for (int d = 0; d < 3; ++d) {
    Eigen::Vector3d e = Eigen::Vector3d::Zero();
    e[d] = 1e-5;
    fd.col(d) = (p.deformation.displacement(x + e) - p.deformation.displacement(x - e)) / 2e-5;
  }
  EXPECT_LT((fd - p.deformation.jacobian(x)).norm(), 1e-6);
  o.deform_mm = 40;
  EXPECT_THROW(draw_synth_params(o), InputError);
}

TEST(Synth, ShapeThatDoesNotFitIsRefused) {
  SynthParams p = draw_synth_params(clean_options(SynthShape::sphere));
  p.shape.radius = 31;
  EXPECT_THROW(render_synth(p), InputError);
}

// --- reproducibility -----------------------------------------------------------------------

TEST(Synth, SameSeedSameCaseOtherSeedOtherCase) {
  SynthOptions o;
  o.shape = SynthShape::blob;
  o.random_pose = true;
  o.deform_mm = 2;
  o.noise = SynthNoise::rician;
  o.bias = 0.2;
  o.seed = 42;
  const SynthResult a = render_synth(draw_synth_params(o)), b = render_synth(draw_synth_params(o));
  EXPECT_EQ(a.image.data, b.image.data);
  EXPECT_EQ(a.truth.data, b.truth.data);
  EXPECT_EQ(a.truth_mesh.V, b.truth_mesh.V);
  o.seed = 43;
  const SynthResult c = render_synth(draw_synth_params(o));
  EXPECT_NE(a.truth.data, c.truth.data);
}

TEST(Synth, ParamsJsonRegeneratesTheSameCase) {
  SynthOptions o;
  o.shape = SynthShape::aneurysm;
  o.size = {48, 52, 40};
  o.spacing = {1.1, 1.0, 1.4};
  o.random_pose = true;
  o.deform_mm = 2.5;
  o.bias = 0.3;
  o.noise = SynthNoise::gaussian;
  o.snr = 6;
  o.seed = 9;
  const SynthParams p = draw_synth_params(o);
  const nlohmann::json j = p;
  const SynthParams q = synth_params_from_json(nlohmann::json::parse(j.dump()));
  const nlohmann::json jq = q;
  EXPECT_EQ(j, jq);
  const SynthResult a = render_synth(p), b = render_synth(q);
  EXPECT_EQ(a.image.data, b.image.data);
  EXPECT_EQ(a.truth.data, b.truth.data);
  nlohmann::json broken = j;
  broken.erase("deformation");
  EXPECT_THROW(synth_params_from_json(broken), InputError);
}

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(SynthCli, WritesTheCaseAndRegeneratesItFromParams) {
  const auto dir = test::scratch_dir("synth-cli");
  const auto a = dir / "a", b = dir / "b";
  auto first = test::run_mrsnake(
      "-q synth --shape blob --size 40 --spacing 1,1,1.2 --pose random --deform 2 --noise rician "
      "--snr 5 --bias 0.2 --seed 17 --json -o " +
      a.string());
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const auto summary = nlohmann::json::parse(first.output);
  EXPECT_GT(summary.at("object_voxels").get<int>(), 1000);
  for (const char* f : {"image.nii.gz", "truth.nii.gz", "truth.vtp", "params.json"})
    EXPECT_TRUE(std::filesystem::exists(a / f)) << f;
  const auto params = nlohmann::json::parse(file_bytes(a / "params.json"));
  EXPECT_EQ(params.at("label").get<int>(), 1);
  EXPECT_EQ(params.at("seed").get<int>(), 17);

  auto again = test::run_mrsnake("-q synth --params " + (a / "params.json").string() + " -o " + b.string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const Volume ia = read_volume((a / "image.nii.gz").string()), ib = read_volume((b / "image.nii.gz").string());
  EXPECT_EQ(ia.data, ib.data);
  EXPECT_EQ(ia.spacing, ib.spacing);
  EXPECT_EQ(file_bytes(a / "image.nii.gz"), file_bytes(b / "image.nii.gz"));
  EXPECT_EQ(file_bytes(a / "truth.nii.gz"), file_bytes(b / "truth.nii.gz"));
  EXPECT_EQ(file_bytes(a / "params.json"), file_bytes(b / "params.json"));

  // The written truth scores perfectly against itself, and the truth mesh against the
  // truth label's own surface is within a voxel.
  auto eval = test::run_mrsnake("evaluate --seg " + (a / "truth.nii.gz").string() + " --truth " +
                                (b / "truth.nii.gz").string() + " --json");
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  EXPECT_EQ(nlohmann::json::parse(eval.output).at("dice").get<double>(), 1.0);
  std::filesystem::remove_all(dir);
}

TEST(SynthCli, BadInputExitCodes) {
  const auto dir = test::scratch_dir("synth-bad");
  const std::string out = " -o " + (dir / "x").string();
  EXPECT_EQ(test::run_mrsnake("synth --shape cube" + out).exit_code, 2);
  EXPECT_EQ(test::run_mrsnake("synth --size 4,4" + out).exit_code, 2);
  EXPECT_EQ(test::run_mrsnake("synth --contrast 200" + out).exit_code, 2);
  EXPECT_EQ(test::run_mrsnake("synth --size 4" + out).exit_code, 3);
  EXPECT_EQ(test::run_mrsnake("synth --from-image a.nii.gz --from-labels b.nii.gz --size 32" + out).exit_code, 2);
  auto fold = test::run_mrsnake("synth --deform 40" + out);
  EXPECT_EQ(fold.exit_code, 3);
  EXPECT_NE(fold.output.find("--deform"), std::string::npos) << fold.output;
  auto missing = test::run_mrsnake("synth --from-image " + (dir / "no.nii.gz").string() + " --from-labels " +
                                   (dir / "no2.nii.gz").string() + out);
  EXPECT_EQ(missing.exit_code, 3) << missing.output;
  EXPECT_NE(missing.output.find("does not exist"), std::string::npos) << missing.output;
  EXPECT_EQ(test::run_mrsnake("synth --params " + (dir / "none.json").string() + out).exit_code, 3);
  EXPECT_EQ(test::run_mrsnake("synth --params " + (dir / "none.json").string() + " --seed 3" + out).exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "x" / "image.nii.gz"));
  std::filesystem::remove_all(dir);
}

// --- from a real volume -----------------------------------------------------------------------

TEST(SynthFromImage, NoWarpReproducesTheSourceAndAWarpIsExactlyKnown) {
  // A "real" image: a rendered blob with noise, and its labels with the object as 3.
  SynthOptions src;
  src.shape = SynthShape::blob;
  src.size = {48, 44, 40};
  src.spacing = {1.0, 1.2, 1.1};
  const SynthResult source = render_synth(draw_synth_params(src));
  // Placed with a rotated direction matrix and an offset origin: all geometry is physical.
  SynthResult placed = source;
  for (Volume* v : {&placed.image, &placed.truth}) {
    v->direction = {0, -1, 0, 1, 0, 0, 0, 0, 1};
    v->origin = {12, -30, 7};
  }
  Volume labels = placed.truth;
  for (float& v : labels.data) v = v == kTruthLabel ? 3.0f : 0.0f;
  Volume mask = labels;
  for (float& v : mask.data) v = v == 3.0f ? 1.0f : 0.0f;

  SynthOptions o;
  o.source_image = "image";
  o.source_labels = "labels";
  o.source_label = 3;
  o.noise = SynthNoise::none;
  o.blur_mm = 0;
  const SynthResult same = render_from_image(draw_synth_params(o, &mask), placed.image, labels);
  EXPECT_EQ(same.truth.data, object_mask(source.truth).data);
  EXPECT_EQ(same.truth.direction, labels.direction);
  EXPECT_EQ(same.truth.origin, labels.origin);
  for (std::size_t i = 0; i < same.image.data.size(); ++i) ASSERT_NEAR(same.image.data[i], source.image.data[i], 1e-3);

  o.deform_mm = 3;
  o.random_pose = true;
  const SynthParams p = draw_synth_params(o, &mask);
  const SynthResult warped = render_from_image(p, placed.image, labels);
  // truth(x) = [mask interpolated at M(x) >= 0.5], checked here with our own interpolation.
  std::size_t checked = 0, wrong = 0, changed = 0;
  for (std::size_t k = 0; k < mask.size[2]; ++k)
    for (std::size_t j = 0; j < mask.size[1]; ++j)
      for (std::size_t i = 0; i < mask.size[0]; ++i) {
        const auto c = mask.index_to_physical(i, j, k);
        const double m = trilinear(mask, p.to_reference({c[0], c[1], c[2]}));
        if (std::abs(m - 0.5) < 1e-3) continue;
        ++checked;
        wrong += (m >= 0.5) != (warped.truth.at(i, j, k) == kTruthLabel);
        changed += warped.truth.at(i, j, k) != mask.at(i, j, k);
      }
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(checked, mask.num_voxels() * 9 / 10);
  EXPECT_GT(changed, 100u);  // the warp did move the object
  EXPECT_TRUE(topology_report(warped.truth_mesh).is_closed_genus0());
  // The truth mesh lies on the 0.5 level of the (binary) truth volume.
  double on = 0;
  for (int v = 0; v < warped.truth_mesh.num_vertices(); ++v)
    on += trilinear(warped.truth, warped.truth_mesh.V.row(v).transpose());
  EXPECT_NEAR(on / warped.truth_mesh.num_vertices(), 0.5, 0.05);
  // The pose turns about the object's centroid (physical), so the object stays in view.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::size_t count = 0;
  for (std::size_t k = 0; k < mask.size[2]; ++k)
    for (std::size_t j = 0; j < mask.size[1]; ++j)
      for (std::size_t i = 0; i < mask.size[0]; ++i)
        if (mask.at(i, j, k) != 0) {
          const auto c = mask.index_to_physical(i, j, k);
          centroid += Eigen::Vector3d(c[0], c[1], c[2]);
          ++count;
        }
  EXPECT_LT((p.pose.centre - centroid / count).norm(), 1e-6);
}

TEST(SynthFromImage, RealBrainMriHippocampus) {
  MRSNAKE_REQUIRE_DATA(image, "volumes/MRIcrop-orig.gipl.gz");
  MRSNAKE_REQUIRE_DATA(labels, "volumes/MRIcrop-seg.gipl.gz");
  const auto dir = test::scratch_dir("synth-real");
  auto r = test::run_mrsnake("-q synth --from-image " + image + " --from-labels " + labels +
                             " --label 4 --deform 3 --pose random --noise rician --snr 8 --seed 3 --json -o " +
                             dir.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Volume source = read_volume(image), out = read_volume((dir / "image.nii.gz").string());
  EXPECT_EQ(source.size, out.size);
  EXPECT_EQ(source.spacing, out.spacing);
  EXPECT_GT(nlohmann::json::parse(r.output).at("object_voxels").get<int>(), 500);
  const auto params = nlohmann::json::parse(file_bytes(dir / "params.json"));
  EXPECT_EQ(params.at("source").at("label").get<int>(), 4);
  auto again =
      test::run_mrsnake("-q synth --params " + (dir / "params.json").string() + " -o " + (dir / "again").string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(out.data, read_volume((dir / "again" / "image.nii.gz").string()).data);
  EXPECT_EQ(read_volume((dir / "truth.nii.gz").string()).data,
            read_volume((dir / "again" / "truth.nii.gz").string()).data);
  auto absent = test::run_mrsnake("synth --from-image " + image + " --from-labels " + labels + " --label 77 -o " +
                                  (dir / "absent").string());
  EXPECT_EQ(absent.exit_code, 3) << absent.output;
  std::filesystem::remove_all(dir);
}

TEST(SynthFromImage, ComponentMakesTheTruthOfOnePartOfTheLabel) {
  // Label 5 on two balls (radius 6 about voxel (9, 10, 10), radius 4 about (25, 10, 10)) and
  // label 2 on a third; the image is bright on all three.
  const auto dir = test::scratch_dir("synth-parts");
  Volume labels;
  labels.size = {34, 20, 20};
  labels.data.assign(labels.num_voxels(), 0.0f);
  std::size_t small_voxels = 0;
  for (std::size_t k = 0; k < labels.size[2]; ++k)
    for (std::size_t j = 0; j < labels.size[1]; ++j)
      for (std::size_t i = 0; i < labels.size[0]; ++i) {
        const double y = j - 10.0, z = k - 10.0, a = i - 9.0, b = i - 25.0, c = i - 25.0, cy = j - 2.0;
        if (a * a + y * y + z * z <= 36.0) labels.at(i, j, k) = 5.0f;
        if (b * b + y * y + z * z <= 16.0) {
          labels.at(i, j, k) = 5.0f;
          ++small_voxels;
        }
        if (c * c + cy * cy + (k - 3.0) * (k - 3.0) <= 2.0) labels.at(i, j, k) = 2.0f;
      }
  Volume image = labels;
  for (float& v : image.data) v = v > 0 ? 100.0f : 20.0f;
  const std::string image_path = (dir / "image.nii.gz").string(), labels_path = (dir / "labels.nii.gz").string();
  write_volume(image_path, image, VoxelType::float32);
  write_volume(labels_path, labels, VoxelType::uint8);
  const std::string from = "-q synth --from-image " + image_path + " --from-labels " + labels_path + " --label 5 ";

  // No pose and no deformation: the truth is exactly the second part's voxels.
  const auto r = test::run_mrsnake(from + "--component 2 --seed 4 -o " + (dir / "part2").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const Volume truth = read_volume((dir / "part2" / "truth.nii.gz").string());
  EXPECT_EQ(static_cast<std::size_t>(std::count(truth.data.begin(), truth.data.end(), float(kTruthLabel))),
            small_voxels);
  EXPECT_EQ(truth.at(25, 10, 10), float(kTruthLabel));
  EXPECT_EQ(truth.at(9, 10, 10), 0.0f);
  const auto params = nlohmann::json::parse(file_bytes(dir / "part2" / "params.json"));
  EXPECT_EQ(params.at("source").at("component").get<int>(), 2);
  // Warped, and regenerated from params.json with the same part.
  const auto warped =
      test::run_mrsnake(from + "--component 2 --pose random --deform 1.5 --seed 4 -o " + (dir / "warped").string());
  ASSERT_EQ(warped.exit_code, 0) << warped.output;
  const auto again = test::run_mrsnake("-q synth --params " + (dir / "warped" / "params.json").string() + " -o " +
                                       (dir / "again").string());
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(read_volume((dir / "warped" / "truth.nii.gz").string()).data,
            read_volume((dir / "again" / "truth.nii.gz").string()).data);
  // Without --component, both balls; a part that does not exist is an input error.
  const auto both = test::run_mrsnake(from + "--seed 4 -o " + (dir / "both").string());
  ASSERT_EQ(both.exit_code, 0) << both.output;
  EXPECT_NE(both.output.find("the label has several parts"), std::string::npos) << both.output;
  const Volume both_truth = read_volume((dir / "both" / "truth.nii.gz").string());
  EXPECT_EQ(both_truth.at(9, 10, 10), float(kTruthLabel));
  EXPECT_EQ(both_truth.at(25, 10, 10), float(kTruthLabel));
  const auto missing = test::run_mrsnake(from + "--component 3 -o " + (dir / "part3").string());
  EXPECT_EQ(missing.exit_code, 3) << missing.output;
  EXPECT_NE(missing.output.find("label 5 has 2 connected parts, so there is no part 3"), std::string::npos)
      << missing.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "part3" / "truth.nii.gz"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mrsnake
