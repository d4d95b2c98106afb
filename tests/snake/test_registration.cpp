// The registration route of the initialization: ITK's similarity registration of the
// model's reference image recovers a known pose, its guards reject what it must, the
// reference image section survives the model round trip and a damaged one is refused, and
// `segment --init register` reaches the end-to-end bound.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/primitives.h"
#include "snake/image_pyramid.h"
#include "snake/initialize.h"
#include "model/snake_adapter.h"
#include "snake/reference_image.h"
#include "snake/registration_itk.h"
#include "snake/segment.h"
#include "tests/support/midpoint_frame_model.h"
#include "phantoms/synth.h"
#include "tests/test_support.h"
#include "tests/wavelets/hierarchies.h"
#include "model/model_io.h"
#include "model/sections.h"

using namespace mrsnake;
namespace fs = std::filesystem;

namespace {

// A known similarity T(x) = c + t + s·R·(x − c) about the image centre.
SimilarityParams known_pose(const Eigen::Vector3d& centre) {
  SimilarityParams p;
  p.centre = centre;
  p.rotation = Eigen::AngleAxisd(10.0 * M_PI / 180.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  p.scale = 1.06;
  p.translation = Eigen::Vector3d(3.2, -2.5, 1.7);
  return p;
}

struct PosedPair {
  SynthResult reference, target;
  SimilarityParams pose;
};

// One blob rendered twice: in its own frame (the reference) and moved by a known pose.
PosedPair posed_pair(SynthShape shape, int size, double snr) {
  SynthOptions o;
  o.shape = shape;
  o.size = {size, size, size};
  o.snr = snr;
  o.seed = 5;
  SynthParams params = draw_synth_params(o);
  PosedPair pair;
  pair.reference = render_synth(params);
  pair.pose = known_pose(params.pose.centre);
  params.pose = pair.pose;
  params.options.seed = 6;  // other noise
  pair.target = render_synth(params);
  return pair;
}

// The crop that build-model --image stores (model_bridge.cpp's add_reference_image).
Volume reference_crop(const Volume& image, const RowMatrixX3d& V) {
  const IntensityWindow window = robust_intensity_window(image);
  Volume crop = make_reference_crop(image, V);
  apply_intensity_window(crop, window);
  return crop;
}

std::vector<const Volume*> pointers(const std::vector<Volume>& pyramid) {
  std::vector<const Volume*> p;
  for (const Volume& v : pyramid) p.push_back(&v);
  return p;
}

Eigen::Vector3d apply_pose(const SimilarityParams& p, const Eigen::Vector3d& x) {
  return p.centre + p.translation + p.scale * (p.rotation * (x - p.centre));
}

using test::read_all;
using test::write_all;

/// A synthetic sphere (SNR 8) and a model of it: an icosahedron subdivided twice, of the given
/// radius (<= 0: the truth's mean radius) at the truth's centre, without lifting.
struct SphereCase {
  SynthResult target;
  Eigen::RowVector3d centre;
  double radius = 0;
  RowMatrixX3d finest;
  SnakeModel model;
};
SphereCase sphere_case(const std::array<int, 3>& size, int seed, double radius) {
  SynthOptions o;
  o.shape = SynthShape::sphere;
  o.size = size;
  o.snr = 8;
  o.seed = seed;
  SphereCase c;
  c.target = render_synth(draw_synth_params(o));
  c.centre = c.target.truth_mesh.V.colwise().mean();
  c.radius = radius;
  if (c.radius <= 0) {
    for (int v = 0; v < c.target.truth_mesh.num_vertices(); ++v)
      c.radius += (c.target.truth_mesh.V.row(v) - c.centre).norm();
    c.radius /= c.target.truth_mesh.num_vertices();
  }
  const TriMesh ico = icosahedron();
  const SubdivisionConnectivity conn = subdivide_connectivity(ico.F, 12, 2);
  c.finest = test::sphere_directions(conn, ico.V) * c.radius;
  c.finest.rowwise() += c.centre;
  c.model = midpoint_frame_model(conn, c.finest);
  return c;
}

}  // namespace

struct PoseErrors {
  double angle_deg = 0, scale = 0, centre_mm = 0, surface_mean_mm = 0, surface_max_mm = 0;
};

// The wall-clock guard off: under a sanitizer or on a loaded machine it would stop the
// optimizer early (1 s once did so under ASan), and these tests judge the converged result.
ReferenceRegistrationOptions untimed() {
  ReferenceRegistrationOptions o;
  o.itk.max_seconds = 1e9;
  return o;
}

// Registers the reference crop of `pair` to its posed target and measures the errors
// against the known pose on the reference's truth surface.
PoseErrors register_and_measure(const PosedPair& pair, const char* name) {
  const Volume crop = reference_crop(pair.reference.image, pair.reference.truth_mesh.V);
  Volume normalized = pair.target.image;
  normalize_intensities(normalized);
  const std::vector<Volume> pyramid = build_pyramid(normalized, 4);
  const ReferenceRegistration r = register_reference(crop, pointers(pyramid), 1.0, 0.0, untimed());
  PoseErrors e;
  EXPECT_TRUE(r.ran) << r.rejection;
  EXPECT_TRUE(r.accepted) << r.rejection;
  if (!r.accepted) return {1e9, 1e9, 1e9, 1e9, 1e9};
  EXPECT_LT(r.result.final_metric, r.result.initial_metric);
  e.angle_deg = Eigen::AngleAxisd(r.pose.rotation.transpose() * pair.pose.rotation).angle() * 180.0 / M_PI;
  e.scale = std::abs(r.pose.scale / pair.pose.scale - 1.0);
  const RowMatrixX3d& V = pair.reference.truth_mesh.V;
  for (int v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d x = V.row(v).transpose();
    const double d = (r.pose.apply(x) - apply_pose(pair.pose, x)).norm();
    e.surface_mean_mm += d / V.rows();
    e.surface_max_mm = std::max(e.surface_max_mm, d);
  }
  const Eigen::Vector3d c = V.colwise().mean().transpose();
  e.centre_mm = (r.pose.apply(c) - apply_pose(pair.pose, c)).norm();
  std::printf("%s: registration %.3f s on pyramid level %d, metric %.4f -> %.4f, iterations", name, r.seconds,
              r.pyramid_level, r.result.initial_metric, r.result.final_metric);
  for (int it : r.result.iterations) std::printf(" %d", it);
  std::printf(
      ", edge radius %.1f mm (%s)\n  rotation error %.3f deg, scale error %.3f%%, centre error %.3f mm, "
      "surface error mean %.3f max %.3f mm\n",
      r.result.edge_radius_mm, r.result.stop_condition.c_str(), e.angle_deg, 100 * e.scale, e.centre_mm,
      e.surface_mean_mm, e.surface_max_mm);
  return e;
}

TEST(Registration, RecoversAKnownSimilarity) {
  // An ellipsoid with three distinct axes: its pose is fully determined by the image
  // (1 mm voxels; pose: 10 deg, scale 1.06, shift 4.4 mm).
  const PoseErrors e = register_and_measure(posed_pair(SynthShape::ellipsoid, 64, 8.0), "ellipsoid");
  EXPECT_LT(e.angle_deg, 2.0);
  EXPECT_LT(e.scale, 0.02);
  EXPECT_LT(e.centre_mm, 1.0);
  EXPECT_LT(e.surface_mean_mm, 1.0);
}

TEST(Registration, PlacesTheSurfaceOfABlobWithinAVoxel) {
  // A blob is nearly round, so its rotation is weakly determined; what counts is where
  // its surface lands.
  const PoseErrors e = register_and_measure(posed_pair(SynthShape::blob, 64, 8.0), "blob");
  EXPECT_LT(e.centre_mm, 1.0);
  EXPECT_LT(e.surface_mean_mm, 1.0);
  EXPECT_LT(e.scale, 0.02);
}

TEST(Registration, StopsALevelWhenTheMetricStopsChanging) {
  // The metric-change stop: with a threshold no change can pass (0), no level stops on it;
  // with one every change passes (a 100% change), each level stops as soon as its window
  // is full, i.e. after window + 1 iterations, and says so.
  const PosedPair pair = posed_pair(SynthShape::ellipsoid, 48, 8.0);
  const Volume crop = reference_crop(pair.reference.image, pair.reference.truth_mesh.V);
  Volume normalized = pair.target.image;
  normalize_intensities(normalized);
  RegistrationOptions o;
  o.max_seconds = 1e9;
  o.iterations_per_level = 25;
  o.min_relative_change = 0;
  const RegistrationResult full = register_similarity(crop, normalized, o);
  EXPECT_EQ(full.converged_levels, 0);
  ASSERT_EQ(full.iterations.size(), o.shrink_factors.size());
  o.min_relative_change = 1.0;
  o.convergence_window = 3;
  const RegistrationResult early = register_similarity(crop, normalized, o);
  EXPECT_EQ(early.converged_levels, static_cast<int>(o.shrink_factors.size()));
  ASSERT_EQ(early.iterations.size(), o.shrink_factors.size());
  for (std::size_t l = 0; l < early.iterations.size(); ++l) {
    EXPECT_EQ(early.iterations[l], o.convergence_window + 1) << "level " << l;
    EXPECT_GT(full.iterations[l], early.iterations[l]) << "level " << l;
  }
  EXPECT_NE(early.stop_condition.find("metric change"), std::string::npos) << early.stop_condition;
  // Still an improvement on the start (the best parameters seen are returned).
  EXPECT_LT(early.final_metric, early.initial_metric);
}

TEST(Registration, ThinSlabsShrinkLessAndASpentBudgetStillReportsEveryLevel) {
  // A reference crop only 9 voxels thick: a block factor of 4 would leave 2 voxels, so the
  // coarse level takes the largest factor that leaves 4 (here 2), for both images alike.
  const PosedPair pair = posed_pair(SynthShape::ellipsoid, 48, 8.0);
  const Volume crop = reference_crop(pair.reference.image, pair.reference.truth_mesh.V);
  ASSERT_GE(crop.size[2], 9u);
  const long mid = static_cast<long>(crop.size[2] / 2);
  const Volume slab = crop_volume(crop, {0, 0, mid - 4},
                                  {static_cast<long>(crop.size[0]) - 1, static_cast<long>(crop.size[1]) - 1, mid + 4});
  ASSERT_EQ(slab.size[2], 9u);
  Volume normalized = pair.target.image;
  normalize_intensities(normalized);
  RegistrationOptions o;
  o.max_seconds = 1e9;
  const RegistrationResult r = register_similarity(slab, normalized, o);
  ASSERT_EQ(r.iterations.size(), o.shrink_factors.size());
  for (int n : r.iterations) EXPECT_GT(n, 0);
  EXPECT_LT(r.final_metric, r.initial_metric);
  // No time at all: the first level stops at its first iteration, the others do not run,
  // and each still has its entry.
  o.max_seconds = 0;
  const RegistrationResult spent = register_similarity(slab, normalized, o);
  ASSERT_EQ(spent.iterations.size(), o.shrink_factors.size());
  EXPECT_EQ(spent.iterations[0], 1);
  for (std::size_t l = 1; l < spent.iterations.size(); ++l) EXPECT_EQ(spent.iterations[l], 0) << "level " << l;
  EXPECT_EQ(spent.stop_condition, "time budget spent");
}

TEST(Registration, StartsFromAGivenTranslation) {
  // The target's frame moved 60 mm away: from the identity there is no overlap; from the
  // right start translation the pose is found again (the retry of segment's registration
  // routes starts from the moments' shift this way).
  PosedPair pair = posed_pair(SynthShape::ellipsoid, 48, 8.0);
  const Volume crop = reference_crop(pair.reference.image, pair.reference.truth_mesh.V);
  Volume normalized = pair.target.image;
  normalize_intensities(normalized);
  std::vector<Volume> pyramid = build_pyramid(normalized, 4);
  const Eigen::Vector3d shift(60.0, 0.0, -60.0);
  for (Volume& v : pyramid)
    for (int a = 0; a < 3; ++a) v.origin[a] += shift[a];
  EXPECT_FALSE(register_reference(crop, pointers(pyramid), 1.0, 0.0, untimed()).accepted);
  const ReferenceRegistration r = register_reference(crop, pointers(pyramid), 1.0, 0.0, untimed(), shift);
  ASSERT_TRUE(r.accepted) << r.rejection;
  double mean_error = 0;
  const RowMatrixX3d& V = pair.reference.truth_mesh.V;
  for (int v = 0; v < V.rows(); ++v) {
    const Eigen::Vector3d x = V.row(v).transpose();
    mean_error += (r.pose.apply(x) - (apply_pose(pair.pose, x) + shift)).norm() / V.rows();
  }
  EXPECT_LT(mean_error, 1.0);
}

TEST(Registration, RejectsAScaleOutsideItsRangeAndAnImageElsewhere) {
  const PosedPair pair = posed_pair(SynthShape::blob, 48, 8.0);
  const Volume crop = reference_crop(pair.reference.image, pair.reference.truth_mesh.V);
  Volume normalized = pair.target.image;
  normalize_intensities(normalized);
  const std::vector<Volume> pyramid = build_pyramid(normalized, 4);
  ReferenceRegistrationOptions narrow;
  narrow.min_scale = 0.5;
  narrow.max_scale = 1.03;  // the true scale is 1.06
  const ReferenceRegistration r = register_reference(crop, pointers(pyramid), 1.0, 0.0, narrow);
  EXPECT_TRUE(r.ran);
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.rejection.find("scale"), std::string::npos) << r.rejection;
  EXPECT_TRUE(r.pose.rotation.isIdentity() && r.pose.scale == 1.0 && r.pose.translation.isZero());

  // An image far from the reference: no overlap, a rejection with its reason, no throw.
  std::vector<Volume> far = pyramid;
  for (Volume& v : far) v.origin[0] += 1000.0;
  const ReferenceRegistration f = register_reference(crop, pointers(far), 1.0, 0.0);
  EXPECT_FALSE(f.ran);
  EXPECT_FALSE(f.accepted);
  EXPECT_NE(f.rejection.find("overlap"), std::string::npos) << f.rejection;
}

TEST(Initialization, MomentsFitAlsoTriesTheModelPose) {
  // Bright slabs of the sphere's own intensity just beside it, inside the moments' region of
  // interest: the threshold's moments land far off (shifted and scaled), while the model's
  // own pose is right. moments+fit must keep the fit from the model's pose.
  SphereCase sc = sphere_case({64, 64, 48}, 5, 0);
  SynthResult& target = sc.target;
  const Eigen::RowVector3d centre = sc.centre;
  const double radius = sc.radius;
  const SnakeModel& model = sc.model;
  double inside = 0, outside = 0;
  std::size_t n_in = 0, n_out = 0;
  for (std::size_t v = 0; v < target.image.num_voxels(); ++v)
    (target.truth.data[v] > 0 ? (inside += target.image.data[v], ++n_in) : (outside += target.image.data[v], ++n_out));
  const double contrast = inside / n_in - outside / n_out;
  // Two slabs, 6 voxels thick, 2 voxels beyond the sphere along +x and along +y: an L that
  // drags the moments' centre off the diagonal and turns their principal axes.
  const auto c = target.image.physical_to_index({centre.x(), centre.y(), centre.z()});
  const long r = std::lround(radius);
  const long ci = std::lround(c[0]), cj = std::lround(c[1]), ck = std::lround(c[2]);
  ASSERT_LT(ci + r + 8, static_cast<long>(target.image.size[0]));
  ASSERT_LT(cj + r + 8, static_cast<long>(target.image.size[1]));
  for (long k = ck - r; k <= ck + r; ++k)
    for (long j = cj - r; j <= cj + r + 8; ++j)
      for (long i = ci - r; i <= ci + r + 8; ++i)
        if (i >= ci + r + 2 || j >= cj + r + 2) target.image.at(i, j, k) += static_cast<float>(contrast);
  SegmentOptions options;
  options.force = ForceMode::step_edge;
  options.count_self_intersections = false;
  // The test's premise: the route's own moments are far off.
  options.init = InitMode::moments;
  options.snake.max_iterations = 0;
  const Similarity moments = segment(target.image, model, options).initial_pose;
  ASSERT_GT((moments.apply(Eigen::Vector3d(centre.transpose())) - centre.transpose()).norm(), 4.0);

  options.init = InitMode::moments_and_fit;
  options.snake.max_iterations = SegmentOptions{}.snake.max_iterations;
  const SegmentResult result = segment(target.image, model, options);
  EXPECT_EQ(result.fit_start, "model pose");
  EXPECT_EQ(segment_report(result)["initial_pose"]["fit_start"], "model pose");
  const Eigen::RowVector3d found = result.surface.V.colwise().mean();
  EXPECT_LT((found - centre).norm(), 0.5);
  double found_radius = 0;
  for (int v = 0; v < result.surface.num_vertices(); ++v) found_radius += (result.surface.V.row(v) - found).norm();
  EXPECT_NEAR(found_radius / result.surface.num_vertices(), radius, 0.5);
}

TEST(Registration, SegmentFallsBackToTheMomentsRouteAndSaysSo) {
  // A reference image that lies far from the new image: the registration is rejected,
  // segment takes moments+fit instead and its report says why.
  SphereCase sc = sphere_case({48, 48, 48}, 3, 12.0);
  const SynthResult& target = sc.target;
  SnakeModel& model = sc.model;
  Volume reference = reference_crop(target.image, sc.finest);
  reference.origin[2] += 1000.0;
  model.reference_image = reference;
  SegmentOptions options;
  options.force = ForceMode::step_edge;
  options.init = InitMode::registration_and_fit;
  options.count_self_intersections = false;
  const SegmentResult r = segment(target.image, model, options);
  ASSERT_TRUE(r.registration.has_value());
  EXPECT_FALSE(r.registration->accepted);
  EXPECT_EQ(r.init, InitMode::moments_and_fit);
  const nlohmann::json rep = segment_report(r);
  EXPECT_EQ(rep["init_used"], "moments+fit");
  EXPECT_EQ(rep["registration"]["accepted"], false);
  EXPECT_EQ(rep["registration"]["fallback"], "moments+fit");
  EXPECT_NE(rep["registration"]["rejection"].get<std::string>().find("overlap"), std::string::npos)
      << rep["registration"];
  // Without a reference image, asking for the registration is an input error; auto falls
  // back silently.
  model.reference_image.reset();
  EXPECT_THROW(segment(target.image, model, options), InputError);
  options.init = InitMode::automatic;
  options.snake.max_iterations = 0;
  EXPECT_EQ(segment(target.image, model, options).init, InitMode::moments_and_fit);
}

TEST(Registration, CropKeepsThePhysicalPlaceAndAverages) {
  // A linear ramp along x: block averages of a linear function equal its value at the
  // block centre, so the crop must read the ramp at its own voxel centres.
  Volume image;
  image.size = {200, 40, 30};
  image.spacing = {0.5, 1.0, 2.0};
  image.origin = {-7, 3, 11};
  image.data.resize(image.num_voxels());
  for (std::size_t k = 0; k < image.size[2]; ++k)
    for (std::size_t j = 0; j < image.size[1]; ++j)
      for (std::size_t i = 0; i < image.size[0]; ++i) {
        const auto p = image.index_to_physical(double(i), double(j), double(k));
        image.at(i, j, k) = static_cast<float>(2.0 * p[0] - p[1] + 0.5 * p[2]);
      }
  RowMatrixX3d V(2, 3);
  V << 10, 10, 20, 60, 30, 50;
  ReferenceImageOptions o;
  o.margin_mm = 5;
  o.max_voxels_per_axis = 40;
  const Volume crop = make_reference_crop(image, V, o);
  // x: [5, 65] mm at 0.5 mm = 121 voxels → factor 4 → 30 voxels of 2 mm.
  EXPECT_EQ(crop.size[0], 30u);
  EXPECT_DOUBLE_EQ(crop.spacing[0], 2.0);
  for (int a = 0; a < 3; ++a) EXPECT_LE(crop.size[a], 40u);
  for (std::size_t k = 0; k < crop.size[2]; k += 3)
    for (std::size_t j = 0; j < crop.size[1]; j += 3)
      for (std::size_t i = 0; i < crop.size[0]; i += 3) {
        const auto p = crop.index_to_physical(double(i), double(j), double(k));
        ASSERT_NEAR(crop.at(i, j, k), 2.0 * p[0] - p[1] + 0.5 * p[2], 1e-3);
      }
  // Points that miss the image.
  RowMatrixX3d far(1, 3);
  far << 1000, 1000, 1000;
  EXPECT_THROW(make_reference_crop(image, far, o), InputError);
}

TEST(ReferenceImageSection, RoundTripsAndRefusesDamage) {
  Volume r;
  r.size = {9, 10, 11};
  r.spacing = {1.5, 2, 2.5};
  r.origin = {-3, 4.25, 100};
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0, 0, 1)).toRotationMatrix();
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) r.direction[3 * a + b] = R(a, b);
  r.data.resize(r.num_voxels());
  for (std::size_t i = 0; i < r.data.size(); ++i) r.data[i] = 0.001f * static_cast<float>(i) - 0.25f;
  const std::vector<std::uint8_t> bytes = serialize_reference_image(r);
  EXPECT_EQ(bytes.size(), 144 + 4 * r.num_voxels() + 8);
  const Volume back = deserialize_reference_image(bytes);
  EXPECT_EQ(back.size, r.size);
  EXPECT_EQ(back.spacing, r.spacing);
  EXPECT_EQ(back.origin, r.origin);
  EXPECT_EQ(back.direction, r.direction);
  EXPECT_EQ(back.data, r.data);

  std::vector<std::uint8_t> flipped = bytes;
  flipped[144 + 40] ^= 0x10;  // one intensity
  EXPECT_THROW(deserialize_reference_image(flipped), InputError);
  std::vector<std::uint8_t> truncated(bytes.begin(), bytes.end() - 9);
  EXPECT_THROW(deserialize_reference_image(truncated), InputError);
  std::vector<std::uint8_t> magic = bytes;
  magic[0] = 'X';
  EXPECT_THROW(deserialize_reference_image(magic), InputError);
  std::vector<std::uint8_t> tiny = bytes;
  tiny[12] = 2;  // n_x = 2: impossible (and the checksum no longer matches either)
  EXPECT_THROW(deserialize_reference_image(tiny), InputError);
  // Every truncation is refused.
  for (std::size_t n = 0; n < bytes.size(); ++n)
    EXPECT_THROW(deserialize_reference_image(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + long(n))),
                 InputError)
        << n << " bytes";
  // Impossible frames and values behind a valid checksum are refused too.
  const auto with_double = [&](std::size_t offset, double value) {
    std::vector<std::uint8_t> b(bytes.begin(), bytes.end() - 8);
    std::memcpy(b.data() + offset, &value, 8);
    const std::uint64_t h = fnv1a64(b.data(), b.size());
    const auto* p = reinterpret_cast<const std::uint8_t*>(&h);
    b.insert(b.end(), p, p + 8);
    return b;
  };
  EXPECT_NO_THROW(deserialize_reference_image(with_double(24, 1.5)));           // the same spacing: still valid
  EXPECT_THROW(deserialize_reference_image(with_double(24, 0.0)), InputError);  // spacing x
  EXPECT_THROW(deserialize_reference_image(with_double(56, std::nan(""))), InputError);  // origin y
  EXPECT_THROW(deserialize_reference_image(with_double(72, 2.0)), InputError);           // direction (0,0)
  EXPECT_THROW(deserialize_reference_image(with_double(32, 1e200)), InputError);         // spacing z, finite
  EXPECT_THROW(deserialize_reference_image(with_double(48, -1e12)), InputError);         // origin x, finite
  std::vector<std::uint8_t> nan_value(bytes.begin(), bytes.end() - 8);
  const float nan = std::nanf("");
  std::memcpy(nan_value.data() + 144, &nan, 4);
  const std::uint64_t h = fnv1a64(nan_value.data(), nan_value.size());
  nan_value.insert(nan_value.end(), reinterpret_cast<const std::uint8_t*>(&h),
                   reinterpret_cast<const std::uint8_t*>(&h) + 8);
  EXPECT_THROW(deserialize_reference_image(nan_value), InputError);
}

TEST(ReferenceImageSection, SurvivesTheModelRoundTripAndADamagedFileIsRefused) {
  const test::Hierarchy h = test::bumpy_sphere(2);  // radius ~10 mm about (3, -2, 5)
  ShapeModel model = make_model(h.conn, h.finest);
  Volume image;
  image.size = {48, 44, 40};
  image.spacing = {1.0, 1.0, 1.25};
  image.origin = {-21, -24, -20};
  image.data.resize(image.num_voxels());
  for (std::size_t k = 0; k < image.size[2]; ++k)
    for (std::size_t j = 0; j < image.size[1]; ++j)
      for (std::size_t i = 0; i < image.size[0]; ++i) {
        const auto p = image.index_to_physical(double(i), double(j), double(k));
        const double d = std::hypot(p[0] - 3, p[1] + 2, p[2] - 5);
        image.at(i, j, k) = static_cast<float>(d < 10 ? 200 + i % 3 : 50 + j % 5);
      }
  add_reference_image(model, image);
  ASSERT_EQ(model.sections.count(kReferenceImageSection), 1u);
  const Volume stored = deserialize_reference_image(model.sections.at(kReferenceImageSection));

  const fs::path dir = test::scratch_dir("reference-image-section");
  save_model((dir / "m.model").string(), model);
  const ShapeModel loaded = load_model((dir / "m.model").string());
  ASSERT_EQ(loaded.sections.count(kReferenceImageSection), 1u);
  EXPECT_EQ(loaded.sections.at(kReferenceImageSection), model.sections.at(kReferenceImageSection));
  const SnakeModel snake = snake_model_from(loaded);
  ASSERT_TRUE(snake.reference_image.has_value());
  EXPECT_EQ(snake.reference_image->data, stored.data);
  EXPECT_EQ(snake.reference_image->origin, stored.origin);
  // The crop holds the surface with its margin (clamped to the image here).
  for (int a = 0; a < 3; ++a) EXPECT_EQ(stored.size[a], image.size[a]);
  // Normalized by the whole image's robust window: the object near 1, the background near 0.
  const auto centre = stored.physical_to_index({3, -2, 5});
  EXPECT_NEAR(stored.at(std::size_t(centre[0]), std::size_t(centre[1]), std::size_t(centre[2])), 1.0, 0.05);
  EXPECT_NEAR(stored.at(0, 0, 0), 0.0, 0.05);

  // One byte of the section file changed: the model is refused with a message naming it.
  const fs::path file = dir / "m.model" / "reference_image.bin";
  ASSERT_TRUE(fs::exists(file));
  std::vector<std::uint8_t> bytes = read_all(file);
  bytes[bytes.size() / 2] ^= 0x01;
  write_all(file, bytes);
  try {
    load_model((dir / "m.model").string());
    ADD_FAILURE() << "a damaged reference image section was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reference_image"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(SegmentCommand, InitRegisterReachesTheEndToEndBound) {
  // build-model --image stores the reference crop; segment --init register places the model
  // by the registration alone (no fit), then the snake.
  const auto dir = test::scratch_dir("segment-register");
  const std::string d = dir.string();
  for (const auto& [name, seed] : {std::pair<std::string, int>{"ref", 32}, {"tgt", 31}}) {
    const auto r = test::run_mrsnake("-q synth --shape blob --size 56 --snr 4 --pose random --deform 2 --seed " +
                                     std::to_string(seed) + " -o " + d + "/" + name);
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  const auto b = test::run_mrsnake("-q build-model --labels " + d + "/ref/truth.nii.gz --label 1 --image " + d +
                                   "/ref/image.nii.gz -o " + d + "/blob.model --faces 8000");
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const auto info = test::run_mrsnake("model-info " + d + "/blob.model --json");
  ASSERT_EQ(info.exit_code, 0) << info.output;
  const nlohmann::json mi = nlohmann::json::parse(info.output);
  ASSERT_TRUE(mi["reference_image"].is_object()) << info.output;
  // The crop is the model's, shared by its structures, not the structure's own section.
  EXPECT_TRUE(mi["shared_reference_image"].is_object());
  EXPECT_FALSE(mi["manifest"]["sections"].contains("reference_image"));

  const auto s = test::run_mrsnake("segment --image " + d + "/tgt/image.nii.gz --model " + d + "/blob.model -o " + d +
                                   "/seg --init register --truth " + d + "/tgt/truth.nii.gz --json -q");
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const nlohmann::json rep = nlohmann::json::parse(s.output);
  EXPECT_EQ(rep["init"], "register");
  EXPECT_EQ(rep["init_used"], "register");
  ASSERT_TRUE(rep.contains("registration"));
  EXPECT_TRUE(rep["registration"]["accepted"].get<bool>()) << rep["registration"].dump();
  EXPECT_LT(rep["registration"]["final_metric"].get<double>(), rep["registration"]["initial_metric"].get<double>());
  EXPECT_TRUE(rep["stage_seconds"].contains("register"));
  EXPECT_EQ(rep["self_intersections"], 0);
  EXPECT_GE(rep["scores"]["dice"].get<double>(), 0.95);
  std::printf("segment --init register: registration %.3f s (scale %.4f, rotation %.2f deg), Dice %.4f ASSD %.3f mm\n",
              rep["stage_seconds"]["register"].get<double>(), rep["registration"]["transform"]["scale"].get<double>(),
              rep["registration"]["transform"]["rotation_deg"].get<double>(), rep["scores"]["dice"].get<double>(),
              rep["scores"]["assd_mm"].get<double>());

  // The default (auto) takes the registration route, then the fit.
  const auto a = test::run_mrsnake("segment --image " + d + "/tgt/image.nii.gz --model " + d + "/blob.model -o " + d +
                                   "/seg-auto --truth " + d + "/tgt/truth.nii.gz --json -q");
  ASSERT_EQ(a.exit_code, 0) << a.output;
  const nlohmann::json ra = nlohmann::json::parse(a.output);
  EXPECT_EQ(ra["init"], "auto");
  EXPECT_EQ(ra["init_used"], "register+fit");
  EXPECT_GE(ra["scores"]["dice"].get<double>(), 0.95);
  fs::remove_all(dir);
}
