#include "phantoms/synth.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "mesh/errors.h"
#include "mesh/marching_cubes.h"
#include "mesh/parallel.h"
#include "mesh/image_filters_itk.h"

namespace mrsnake {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Portable random numbers: std::mt19937_64 and std::seed_seq are specified bit for bit by
/// the standard, the distributions are not, so they are written here.
class Rng {
 public:
  /// One independent stream per purpose, so that e.g. turning the pose on does not change
  /// the shape drawn from the same seed.
  Rng(std::uint64_t seed, std::uint32_t stream) {
    std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), stream};
    engine_.seed(seq);
  }
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  double normal() {  // Box–Muller, both values used
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = 1.0 - uniform();  // (0, 1]
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2 * kPi * u2);
    has_spare_ = true;
    return r * std::cos(2 * kPi * u2);
  }
  Eigen::Vector3d unit_vector() {
    const double z = uniform(-1, 1), phi = uniform(0, 2 * kPi), s = std::sqrt(1 - z * z);
    return {s * std::cos(phi), s * std::sin(phi), z};
  }
  Eigen::Vector3d in_ball(double radius) { return unit_vector() * radius * std::cbrt(uniform()); }

 private:
  std::mt19937_64 engine_;
  bool has_spare_ = false;
  double spare_ = 0;
};

enum Stream : std::uint32_t { kShapeStream = 1, kPoseStream, kDeformStream, kBiasStream, kNoiseStream };

Eigen::Vector3d vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

double smooth_min(double a, double b, double k) {
  if (k <= 0) return std::min(a, b);
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}
double smooth_max(double a, double b, double k) { return -smooth_min(-a, -b, k); }

/// Approximate signed distance to an ellipsoid (exact zero level; Quílez's bound).
double ellipsoid_function(const Eigen::Vector3d& p, const Eigen::Vector3d& r) {
  const double k0 = p.cwiseQuotient(r).norm();
  const double k1 = p.cwiseQuotient(r.cwiseProduct(r)).norm();
  if (k1 < 1e-12) return -r.minCoeff();
  return k0 * (k0 - 1.0) / k1;
}

double blob_radius(const ShapeParams& s, const Eigen::Vector3d& u) {
  double g = 0;
  for (std::size_t k = 0; k < s.bump_directions.size(); ++k)
    g += s.bump_heights[k] * std::exp(s.bump_concentrations[k] * (u.dot(s.bump_directions[k]) - 1.0));
  return s.base_radius * (1.0 + g);
}

/// Exact distance to the aneurysm's centreline arc.
double arc_distance(const ShapeParams& s, const Eigen::Vector3d& x) {
  const Eigen::Vector3d c(0, s.arc_offset - s.arc_radius, 0);
  const Eigen::Vector3d q = x - c;
  const double theta = std::atan2(q.y(), q.x());
  if (std::abs(theta - kPi / 2) <= s.arc_half_angle) return std::hypot(std::hypot(q.x(), q.y()) - s.arc_radius, q.z());
  double best = std::numeric_limits<double>::infinity();
  for (double sign : {-1.0, 1.0}) {
    const double a = kPi / 2 + sign * s.arc_half_angle;
    const Eigen::Vector3d e = c + s.arc_radius * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
    best = std::min(best, (x - e).norm());
  }
  return best;
}

/// The object's implicit function in the reference frame (negative inside).
double shape_function(const ShapeParams& s, const Eigen::Vector3d& x) {
  switch (s.kind) {
    case SynthShape::sphere: return x.norm() - s.radius;
    case SynthShape::ellipsoid: return ellipsoid_function(x, s.semi_axes);
    case SynthShape::blob: {
      const double n = x.norm();
      if (n < 1e-12) return -blob_radius(s, Eigen::Vector3d::UnitZ());
      return n - blob_radius(s, x / n);
    }
    case SynthShape::aneurysm: {
      const double tube = arc_distance(s, x) - s.vessel_radius;
      const double sac = (x - s.sac_centre).norm() - s.sac_radius;
      return smooth_min(tube, sac, s.neck_smoothing);
    }
    case SynthShape::heart: {
      const Eigen::Vector3d y = x + Eigen::Vector3d(0, 0, s.z_offset);
      return smooth_max(ellipsoid_function(y, s.semi_axes), y.z() - s.base_height, s.rim_smoothing);
    }
  }
  return 0;
}

/// The heart's outer wall surface (negative inside the wall or the cavity).
double heart_outer_function(const ShapeParams& s, const Eigen::Vector3d& x) {
  const Eigen::Vector3d y = x + Eigen::Vector3d(0, 0, s.z_offset);
  const Eigen::Vector3d outer = s.semi_axes + Eigen::Vector3d::Constant(s.wall_thickness);
  return smooth_max(ellipsoid_function(y, outer), y.z() - s.base_height, s.rim_smoothing);
}

double field_of_view(const std::array<int, 3>& size, const std::array<double, 3>& spacing) {
  return std::min({size[0] * spacing[0], size[1] * spacing[1], size[2] * spacing[2]});
}

ShapeParams draw_shape(SynthShape kind, double fov, Rng& rng) {
  ShapeParams s;
  s.kind = kind;
  switch (kind) {
    case SynthShape::sphere: s.radius = 0.3 * fov; break;
    case SynthShape::ellipsoid:
      s.semi_axes = Eigen::Vector3d(0.34, 0.26, 0.19) * fov;
      for (int d = 0; d < 3; ++d) s.semi_axes[d] *= rng.uniform(0.9, 1.1);
      break;
    case SynthShape::blob: {
      s.base_radius = 0.26 * fov;
      const int bumps = 6;
      for (int k = 0; k < bumps; ++k) {
        s.bump_directions.push_back(rng.unit_vector());
        s.bump_heights.push_back(rng.uniform(-0.25, 0.35));
        s.bump_concentrations.push_back(rng.uniform(2.0, 5.0));
      }
      // Keep the radius within ±35% of the base radius: smooth, star-shaped, inside the image.
      double largest = 0;
      for (int i = 0; i < 2000; ++i) {  // Fibonacci sphere
        const double z = 1 - (2 * i + 1) / 2000.0, r = std::sqrt(1 - z * z), phi = i * kPi * (3 - std::sqrt(5.0));
        const double g = blob_radius(s, {r * std::cos(phi), r * std::sin(phi), z}) / s.base_radius - 1.0;
        largest = std::max(largest, std::abs(g));
      }
      if (largest > 0.35)
        for (double& h : s.bump_heights) h *= 0.35 / largest;
      break;
    }
    case SynthShape::aneurysm: {
      s.vessel_radius = 0.07 * fov * rng.uniform(0.9, 1.1);
      s.arc_radius = 0.45 * fov * rng.uniform(0.9, 1.1);
      s.arc_half_angle = rng.uniform(0.55, 0.7);
      s.sac_radius = s.vessel_radius * rng.uniform(1.6, 2.2);
      s.neck_smoothing = 0.5 * s.vessel_radius;
      s.arc_offset = (s.arc_radius * (1 - std::cos(s.arc_half_angle)) - 1.5 * s.sac_radius) / 2;
      const double along = kPi / 2 + rng.uniform(-0.3, 0.3) * s.arc_half_angle;
      const double tilt = rng.uniform(-0.4, 0.4);
      const Eigen::Vector3d c(0, s.arc_offset - s.arc_radius, 0);
      const Eigen::Vector3d radial(std::cos(along), std::sin(along), 0);
      const Eigen::Vector3d normal = std::cos(tilt) * radial + std::sin(tilt) * Eigen::Vector3d::UnitZ();
      s.sac_centre = c + s.arc_radius * radial + (s.vessel_radius + 0.5 * s.sac_radius) * normal;
      break;
    }
    case SynthShape::heart: {
      const double a = 0.17 * fov * rng.uniform(0.9, 1.1);
      s.semi_axes = Eigen::Vector3d(a, a * rng.uniform(0.85, 1.0), 0.3 * fov * rng.uniform(0.9, 1.1));
      s.wall_thickness = 0.07 * fov * rng.uniform(0.85, 1.15);
      s.base_height = s.semi_axes.z() * rng.uniform(0.35, 0.55);
      s.rim_smoothing = 0.3 * s.wall_thickness;
      s.z_offset = (s.base_height - s.semi_axes.z() - s.wall_thickness) / 2;
      break;
    }
  }
  return s;
}

Volume make_grid(const SynthOptions& o) {
  Volume v;
  for (int d = 0; d < 3; ++d) {
    v.size[d] = static_cast<std::size_t>(o.size[d]);
    v.spacing[d] = o.spacing[d];
    v.origin[d] = -0.5 * (o.size[d] - 1) * o.spacing[d];  // centred on the physical origin
  }
  v.data.assign(v.num_voxels(), 0.0f);
  return v;
}

Eigen::Vector3d voxel_centre(const Volume& v, double i, double j, double k) {
  return vec(v.index_to_physical(i, j, k));
}

void validate(const SynthOptions& o) {
  auto bad = [](const std::string& m) { throw InputError(m); };
  for (int d = 0; d < 3; ++d) {
    if (!o.from_image() && (o.size[d] < 8 || o.size[d] > 2048))
      bad("--size must be between 8 and 2048 voxels per axis");
    if (!o.from_image() && !(std::isfinite(o.spacing[d]) && o.spacing[d] > 0)) bad("--spacing must be positive");
  }
  if (!(std::isfinite(o.snr))) bad("--snr must be a finite number (<= 0 for no noise)");
  if (!(std::isfinite(o.blur_mm) && o.blur_mm >= 0)) bad("--blur must be >= 0 mm");
  if (!(std::isfinite(o.bias) && o.bias >= 0 && o.bias <= 3)) bad("--bias must be between 0 and 3");
  if (!(std::isfinite(o.deform_mm) && o.deform_mm >= 0)) bad("--deform must be >= 0 mm");
  if (!(std::isfinite(o.foreground) && std::isfinite(o.background))) bad("--contrast needs two finite intensities");
  if (!o.from_image() && o.noise != SynthNoise::none && o.snr > 0 && o.foreground == o.background)
    bad("--contrast: foreground and background are equal, so --snr defines no noise; give two different intensities");
  if (o.supersampling < 1 || o.supersampling > 16) bad("--supersampling must be between 1 and 16");
}

/// Draws K Gaussian bumps centred in [lo, hi], scaled so the largest displacement over the
/// box is `amplitude`, and refuses a field that folds space.
DeformationParams draw_deformation(double amplitude, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                                   const Eigen::Vector3d& box_lo, const Eigen::Vector3d& box_hi, double fov, Rng& rng) {
  DeformationParams u;
  u.width_mm = 0.2 * fov;
  if (amplitude <= 0) return u;
  const int bumps = 8;
  for (int k = 0; k < bumps; ++k) {
    Eigen::Vector3d c;
    for (int d = 0; d < 3; ++d) c[d] = rng.uniform(lo[d], hi[d]);
    u.centres.push_back(c);
    u.displacements.push_back(rng.in_ball(1.0));
  }
  const int n = 32;  // samples per axis of the box: under a third of the bump width apart
  auto sample = [&](int i, int j, int k) {
    return Eigen::Vector3d(box_lo.x() + (box_hi.x() - box_lo.x()) * i / (n - 1),
                           box_lo.y() + (box_hi.y() - box_lo.y()) * j / (n - 1),
                           box_lo.z() + (box_hi.z() - box_lo.z()) * k / (n - 1));
  };
  double largest = 0;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) largest = std::max(largest, u.displacement(sample(i, j, k)).norm());
  for (auto& d : u.displacements) d *= amplitude / std::max(largest, 1e-12);
  // p -> p + u(p) is the identity far away; with positive Jacobians everywhere it is a
  // diffeomorphism. They are checked on the samples and at the bump centres, with a margin.
  double smallest_det = std::numeric_limits<double>::infinity();
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        smallest_det =
            std::min(smallest_det, (Eigen::Matrix3d::Identity() + u.jacobian(sample(i, j, k))).determinant());
  for (const auto& c : u.centres)
    smallest_det = std::min(smallest_det, (Eigen::Matrix3d::Identity() + u.jacobian(c)).determinant());
  if (smallest_det < 0.2) {
    std::ostringstream m;
    m << "--deform " << amplitude << " mm is too large for this field of view: the warp would nearly fold "
      << "(smallest Jacobian determinant " << smallest_det << "); use a smaller amplitude, e.g. " << 0.5 * amplitude;
    throw InputError(m.str());
  }
  return u;
}

BiasParams draw_bias(double strength, const Eigen::Vector3d& centre, const Eigen::Vector3d& half_extent, Rng& rng) {
  BiasParams b;
  b.strength = strength;
  b.centre = centre;
  b.half_extent = half_extent;
  double norm = 0;
  for (int i = 0; i < 9; ++i) {
    b.coefficients[i] = rng.uniform(-1, 1);
    norm += std::abs(b.coefficients[i]) * (i >= 3 && i < 6 ? 2.0 / 3.0 : 1.0);
  }
  for (double& c : b.coefficients) c /= std::max(norm, 1e-12);
  return b;
}

/// Blur, bias and noise, in that order, on the contrast image.
void degrade(Volume& image, const SynthParams& p, double contrast, const ProgressFn& progress) {
  const SynthOptions& o = p.options;
  if (o.blur_mm > 0) {
    report(progress, "synth: blur", 0.0);
    image = gaussian_blur(image, o.blur_mm);
  }
  if (p.bias_field.strength > 0) {
    for (std::size_t k = 0; k < image.size[2]; ++k)
      for (std::size_t j = 0; j < image.size[1]; ++j)
        for (std::size_t i = 0; i < image.size[0]; ++i)
          image.at(i, j, k) = static_cast<float>(image.at(i, j, k) * p.bias_field.factor(voxel_centre(image, i, j, k)));
  }
  if (o.noise == SynthNoise::none || o.snr <= 0) return;
  const double sigma = std::abs(contrast) / o.snr;
  Rng rng(o.seed, kNoiseStream);
  report(progress, "synth: noise", 0.0);
  for (float& v : image.data) {
    if (o.noise == SynthNoise::gaussian) {
      v = static_cast<float>(v + sigma * rng.normal());
    } else {  // Rician: the magnitude of a complex signal with Gaussian noise on both channels
      const double re = v + sigma * rng.normal(), im = sigma * rng.normal();
      v = static_cast<float>(std::hypot(re, im));
    }
  }
}

/// Moves each vertex onto the zero level of f by Newton steps along the gradient.
void project_onto_surface(RowMatrixX3d& V, const std::function<double(const Eigen::Vector3d&)>& f, double h,
                          double max_step) {
  parallel_ranges(
      static_cast<std::size_t>(V.rows()),
      [&](std::size_t begin, std::size_t end) {
        for (int v = static_cast<int>(begin); v < static_cast<int>(end); ++v) {
          Eigen::Vector3d x = V.row(v).transpose();
          for (int it = 0; it < 10; ++it) {
            const double fx = f(x);
            if (std::abs(fx) < 1e-9) break;
            Eigen::Vector3d g;
            for (int d = 0; d < 3; ++d) {
              Eigen::Vector3d e = Eigen::Vector3d::Zero();
              e[d] = h;
              g[d] = (f(x + e) - f(x - e)) / (2 * h);
            }
            const double g2 = g.squaredNorm();
            if (g2 < 1e-12) break;
            Eigen::Vector3d step = fx * g / g2;
            if (step.norm() > max_step) step *= max_step / step.norm();
            x -= step;
          }
          V.row(v) = x.transpose();
        }
      },
      4);
}

}  // namespace

// ---------------------------------------------------------------------------------------------

SynthShape parse_synth_shape(const std::string& name) {
  if (name == "sphere") return SynthShape::sphere;
  if (name == "ellipsoid") return SynthShape::ellipsoid;
  if (name == "blob") return SynthShape::blob;
  if (name == "aneurysm") return SynthShape::aneurysm;
  if (name == "heart") return SynthShape::heart;
  throw InputError("unknown shape '" + name + "'; use sphere, ellipsoid, blob, aneurysm or heart");
}

std::string to_string(SynthShape shape) {
  switch (shape) {
    case SynthShape::sphere: return "sphere";
    case SynthShape::ellipsoid: return "ellipsoid";
    case SynthShape::blob: return "blob";
    case SynthShape::aneurysm: return "aneurysm";
    case SynthShape::heart: return "heart";
  }
  return "?";
}

SynthNoise parse_synth_noise(const std::string& name) {
  if (name == "none") return SynthNoise::none;
  if (name == "gaussian") return SynthNoise::gaussian;
  if (name == "rician") return SynthNoise::rician;
  throw InputError("unknown noise '" + name + "'; use none, gaussian or rician");
}

std::string to_string(SynthNoise noise) {
  switch (noise) {
    case SynthNoise::none: return "none";
    case SynthNoise::gaussian: return "gaussian";
    case SynthNoise::rician: return "rician";
  }
  return "?";
}

Eigen::Vector3d DeformationParams::displacement(const Eigen::Vector3d& p) const {
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  const double s = -0.5 / (width_mm * width_mm);
  for (std::size_t k = 0; k < centres.size(); ++k) u += displacements[k] * std::exp(s * (p - centres[k]).squaredNorm());
  return u;
}

Eigen::Matrix3d DeformationParams::jacobian(const Eigen::Vector3d& p) const {
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  const double s = -0.5 / (width_mm * width_mm);
  for (std::size_t k = 0; k < centres.size(); ++k) {
    const Eigen::Vector3d r = p - centres[k];
    const double phi = std::exp(s * r.squaredNorm());
    J += displacements[k] * (2 * s * phi * r).transpose();
  }
  return J;
}

double BiasParams::factor(const Eigen::Vector3d& p) const {
  if (strength <= 0) return 1.0;
  const Eigen::Vector3d x = (p - centre).cwiseQuotient(half_extent);
  const double m[9] = {x.x(),
                       x.y(),
                       x.z(),
                       x.x() * x.x() - 1.0 / 3,
                       x.y() * x.y() - 1.0 / 3,
                       x.z() * x.z() - 1.0 / 3,
                       x.x() * x.y(),
                       x.y() * x.z(),
                       x.z() * x.x()};
  double g = 0;
  for (int i = 0; i < 9; ++i) g += coefficients[i] * m[i];
  return std::exp(strength * g);
}

Eigen::Vector3d SynthParams::to_reference(const Eigen::Vector3d& p) const {
  const Eigen::Vector3d q = p + deformation.displacement(p);
  return pose.centre + pose.rotation.transpose() * (q - pose.centre - pose.translation) / pose.scale;
}

double object_function(const SynthParams& params, const Eigen::Vector3d& p) {
  return params.pose.scale * shape_function(params.shape, params.to_reference(p));
}

SynthParams draw_synth_params(const SynthOptions& options, const Volume* source_mask) {
  validate(options);
  SynthParams p;
  p.options = options;
  Eigen::Vector3d box_lo, box_hi, centre, lo, hi;
  double fov = 0;
  if (options.from_image()) {
    if (!source_mask) throw Error("internal: --from-image needs the source mask to draw its parameters");
    const Volume& m = *source_mask;
    for (int d = 0; d < 3; ++d) {
      p.options.size[d] = static_cast<int>(m.size[d]);
      p.options.spacing[d] = m.spacing[d];
    }
    fov = field_of_view(p.options.size, p.options.spacing);
    box_lo = box_hi = voxel_centre(m, 0, 0, 0);
    for (double i : {0.0, m.size[0] - 1.0})
      for (double j : {0.0, m.size[1] - 1.0})
        for (double k : {0.0, m.size[2] - 1.0}) {
          const Eigen::Vector3d c = voxel_centre(m, i, j, k);
          box_lo = box_lo.cwiseMin(c);
          box_hi = box_hi.cwiseMax(c);
        }
    // Centre the pose on the object, and put the bumps where the object is.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    hi = -lo;
    std::size_t count = 0;
    for (std::size_t k = 0; k < m.size[2]; ++k)
      for (std::size_t j = 0; j < m.size[1]; ++j)
        for (std::size_t i = 0; i < m.size[0]; ++i)
          if (m.at(i, j, k) != 0) {
            const Eigen::Vector3d c = voxel_centre(m, i, j, k);
            sum += c;
            lo = lo.cwiseMin(c);
            hi = hi.cwiseMax(c);
            ++count;
          }
    if (count == 0)
      throw InputError("label " + std::to_string(options.source_label) + " has no voxel in '" + options.source_labels +
                       "'; pick a label that is present with --label");
    centre = sum / static_cast<double>(count);
  } else {
    fov = field_of_view(options.size, options.spacing);
    const Volume grid = make_grid(options);
    box_lo = voxel_centre(grid, 0, 0, 0);
    box_hi = voxel_centre(grid, options.size[0] - 1, options.size[1] - 1, options.size[2] - 1);
    centre = Eigen::Vector3d::Zero();
    lo = -0.3 * (box_hi - box_lo);
    hi = 0.3 * (box_hi - box_lo);
    Rng shape_rng(options.seed, kShapeStream);
    p.shape = draw_shape(options.shape, fov, shape_rng);
  }
  p.pose.centre = centre;
  if (options.random_pose) {
    Rng rng(options.seed, kPoseStream);
    const Eigen::Vector3d axis = rng.unit_vector();
    const double angle = rng.uniform(-15.0, 15.0) * kPi / 180.0;
    p.pose.rotation = Eigen::AngleAxisd(angle, axis).toRotationMatrix();
    p.pose.translation = rng.in_ball(0.05 * fov);
    p.pose.scale = rng.uniform(0.9, 1.1);
  }
  Rng deform_rng(options.seed, kDeformStream);
  p.deformation = draw_deformation(options.deform_mm, lo, hi, box_lo, box_hi, fov, deform_rng);
  Rng bias_rng(options.seed, kBiasStream);
  p.bias_field = draw_bias(options.bias, 0.5 * (box_lo + box_hi),
                           0.5 * (box_hi - box_lo).cwiseMax(Eigen::Vector3d::Constant(1e-6)), bias_rng);
  return p;
}

SynthResult render_synth(const SynthParams& params, const ProgressFn& progress) {
  const SynthOptions& o = params.options;
  if (o.from_image()) throw Error("internal: render_synth called for a --from-image case");
  const bool heart = params.shape.kind == SynthShape::heart;
  const double s = params.pose.scale;
  auto object = [&](const Eigen::Vector3d& p) { return s * shape_function(params.shape, params.to_reference(p)); };
  // The object's and (heart) the outer wall's functions, sharing one mapping of the point.
  auto both = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d x = params.to_reference(p);
    return std::pair<double, double>(s * shape_function(params.shape, x),
                                     heart ? s * heart_outer_function(params.shape, x) : 1.0);
  };
  const double mid = 0.5 * (o.foreground + o.background);
  auto tissue = [&](const Eigen::Vector3d& p) {
    const auto [v, w] = both(p);
    if (v < 0) return o.foreground;
    if (heart) return w < 0 ? o.background : mid;
    return o.background;
  };

  SynthResult r;
  r.truth = make_grid(o);
  r.image = make_grid(o);
  Volume field = make_grid(o);  // the object function at voxel centres, for the mesh
  const std::size_t nx = r.truth.size[0], ny = r.truth.size[1], nz = r.truth.size[2];
  const Eigen::Vector3d sp = vec(r.truth.spacing);
  const double margin = 0.25 * sp.norm();
  const int n = o.supersampling;

  // Values at voxel corners, one z plane at a time (plane k holds the corners at k − 1/2).
  const std::size_t cx = nx + 1, cy = ny + 1;
  auto fill_plane = [&](double kz, std::vector<double>& obj, std::vector<double>& out) {
    for (std::size_t j = 0; j < cy; ++j)
      for (std::size_t i = 0; i < cx; ++i) {
        const Eigen::Vector3d c = voxel_centre(r.truth, i - 0.5, j - 0.5, kz);
        const auto [v, w] = both(c);
        obj[i + cx * j] = v;
        if (heart) out[i + cx * j] = w;
      }
  };
  auto is_mixed = [&](const std::vector<double>& lo, const std::vector<double>& hi, double centre_value, std::size_t i,
                      std::size_t j) {
    bool neg = centre_value < 0, pos = centre_value >= 0;
    double smallest = std::abs(centre_value);
    for (const auto* plane : {&lo, &hi})
      for (std::size_t dj = 0; dj < 2; ++dj)
        for (std::size_t di = 0; di < 2; ++di) {
          const double v = (*plane)[(i + di) + cx * (j + dj)];
          neg = neg || v < 0;
          pos = pos || v >= 0;
          smallest = std::min(smallest, std::abs(v));
        }
    return (neg && pos) || smallest < margin;
  };
  // Slabs of z planes, one per thread; every voxel depends on the parameters only, so the
  // result does not depend on the number of threads.
  auto render_slab = [&](std::size_t k0, std::size_t k1, bool reports) {
    std::vector<double> obj_lo(cx * cy), obj_hi(cx * cy), out_lo, out_hi;
    if (heart) out_lo.resize(cx * cy), out_hi.resize(cx * cy);
    fill_plane(k0 - 0.5, obj_lo, out_lo);
    for (std::size_t k = k0; k < k1; ++k) {
      if (reports) report(progress, "synth: shape", static_cast<double>(k - k0) / (k1 - k0));
      fill_plane(k + 0.5, obj_hi, out_hi);
      for (std::size_t j = 0; j < ny; ++j)
        for (std::size_t i = 0; i < nx; ++i) {
          const Eigen::Vector3d c = voxel_centre(r.truth, i, j, k);
          const auto [v, w] = both(c);
          const bool border = i < 2 || j < 2 || k < 2 || i + 2 >= nx || j + 2 >= ny || k + 2 >= nz;
          if (border && v <= 0)
            throw InputError(
                "the " + to_string(params.shape.kind) +
                " does not fit inside the image (it reaches the border); use a larger --size or --spacing, "
                "a smaller --deform, or another --seed");
          field.at(i, j, k) = static_cast<float>(v);
          r.truth.at(i, j, k) = v < 0 ? kTruthLabel : (heart && w < 0 ? kWallLabel : 0);
          const bool mixed = is_mixed(obj_lo, obj_hi, v, i, j) || (heart && is_mixed(out_lo, out_hi, w, i, j));
          double value;
          if (!mixed) {
            value = v < 0 ? o.foreground : (heart ? (w < 0 ? o.background : mid) : o.background);
          } else {  // partial volume: the mean intensity over n³ sub-voxel samples
            double sum = 0;
            for (int a = 0; a < n; ++a)
              for (int b = 0; b < n; ++b)
                for (int e = 0; e < n; ++e)
                  sum += tissue(
                      voxel_centre(r.truth, i + (e + 0.5) / n - 0.5, j + (b + 0.5) / n - 0.5, k + (a + 0.5) / n - 0.5));
            value = sum / (n * n * n);
          }
          r.image.at(i, j, k) = static_cast<float>(value);
        }
      std::swap(obj_lo, obj_hi);
      if (heart) std::swap(out_lo, out_hi);
    }
  };
  // The slab starting at 0 runs on the calling thread: it reports the progress.
  parallel_ranges(
      nz, [&](std::size_t k0, std::size_t k1) { render_slab(k0, k1, k0 == 0); }, 4);
  report(progress, "synth: shape", 1.0);

  degrade(r.image, params, o.foreground - o.background, progress);

  report(progress, "synth: mesh", 0.0);
  r.truth_mesh = extract_isosurface(field, 0.0, /*inside_is_greater=*/false);
  // Marching cubes interpolates linearly between voxel centres; put the vertices on the
  // analytic surface itself.
  project_onto_surface(r.truth_mesh.V, object, 1e-4 * sp.minCoeff(), 0.5 * sp.minCoeff());
  report(progress, "synth: mesh", 1.0);
  return r;
}

SynthResult render_from_image(const SynthParams& params, const Volume& image, const Volume& labels,
                              const ProgressFn& progress) {
  const SynthOptions& o = params.options;
  if (image.size != labels.size || image.spacing != labels.spacing || image.origin != labels.origin ||
      image.direction != labels.direction)
    throw InputError("'" + o.source_image + "' and '" + o.source_labels +
                     "' are on different grids (size, spacing, origin or direction); give labels on the image's grid");
  Volume mask = labels;
  double inside = 0, outside = 0;
  std::size_t n_in = 0;
  for (std::size_t i = 0; i < mask.num_voxels(); ++i) {
    const bool in = std::lround(labels.data[i]) == o.source_label;
    mask.data[i] = in ? 1.0f : 0.0f;
    (in ? inside : outside) += image.data[i];
    n_in += in;
  }
  if (n_in == 0)
    throw InputError("label " + std::to_string(o.source_label) + " has no voxel in '" + o.source_labels +
                     "'; pick a label that is present with --label");
  const std::size_t n_out = mask.num_voxels() - n_in;
  const double contrast = inside / n_in - (n_out ? outside / n_out : 0.0);

  report(progress, "synth: warp", 0.0);
  Volume dx = mask, dy = mask, dz = mask;
  for (std::size_t k = 0; k < mask.size[2]; ++k)
    for (std::size_t j = 0; j < mask.size[1]; ++j)
      for (std::size_t i = 0; i < mask.size[0]; ++i) {
        const Eigen::Vector3d c = voxel_centre(mask, i, j, k);
        const Eigen::Vector3d d = params.to_reference(c) - c;
        dx.at(i, j, k) = static_cast<float>(d.x());
        dy.at(i, j, k) = static_cast<float>(d.y());
        dz.at(i, j, k) = static_cast<float>(d.z());
      }
  const float padding = *std::min_element(image.data.begin(), image.data.end());
  SynthResult r;
  r.image = warp_volume(image, dx, dy, dz, Interpolation::linear, padding);
  const Volume warped_mask = warp_volume(mask, dx, dy, dz, Interpolation::linear, 0.0f);
  r.truth = warped_mask;
  for (float& v : r.truth.data) v = v >= 0.5f ? kTruthLabel : 0.0f;
  report(progress, "synth: warp", 1.0);

  degrade(r.image, params, contrast, progress);

  report(progress, "synth: mesh", 0.0);
  r.truth_mesh = extract_isosurface(warped_mask, 0.5, /*inside_is_greater=*/true);
  report(progress, "synth: mesh", 1.0);
  return r;
}

// ---------------------------------------------------------------------------------------------
// params.json

namespace {

using nlohmann::json;

json to_j(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }
Eigen::Vector3d vec_from(const json& j) {
  if (!j.is_array() || j.size() != 3)
    throw InputError("malformed synth parameters: expected an array of 3 numbers, got " + j.dump());
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}
std::vector<Eigen::Vector3d> vecs_from(const json& j) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& e : j) out.push_back(vec_from(e));
  return out;
}

}  // namespace

void to_json(nlohmann::json& j, const SynthParams& p) {
  const SynthOptions& o = p.options;
  j = json::object();
  j["format"] = "mrsnake synth parameters";
  j["format_version"] = 1;
  j["label"] = kTruthLabel;
  j["seed"] = o.seed;
  j["size"] = o.size;
  j["spacing"] = o.spacing;
  j["noise"] = to_string(o.noise);
  j["snr"] = o.snr;
  j["snr_definition"] = "|foreground - background| / sigma of the noise (of each channel for rician)";
  j["blur_mm"] = o.blur_mm;
  j["bias"] = o.bias;
  j["pose"] = o.random_pose ? "random" : "none";
  j["deform_mm"] = o.deform_mm;
  if (o.from_image()) {
    j["source"] = {{"image", o.source_image}, {"labels", o.source_labels}, {"label", o.source_label}};
    if (o.source_component > 0) j["source"]["component"] = o.source_component;
  } else {
    j["shape"] = to_string(o.shape);
    j["foreground"] = o.foreground;
    j["background"] = o.background;
    j["supersampling"] = o.supersampling;
    const ShapeParams& s = p.shape;
    json sj = json::object();
    switch (s.kind) {
      case SynthShape::sphere: sj["radius"] = s.radius; break;
      case SynthShape::ellipsoid: sj["semi_axes"] = to_j(s.semi_axes); break;
      case SynthShape::blob: {
        sj["base_radius"] = s.base_radius;
        json dirs = json::array();
        for (const auto& d : s.bump_directions) dirs.push_back(to_j(d));
        sj["bump_directions"] = dirs;
        sj["bump_heights"] = s.bump_heights;
        sj["bump_concentrations"] = s.bump_concentrations;
        break;
      }
      case SynthShape::aneurysm:
        sj["vessel_radius"] = s.vessel_radius;
        sj["arc_radius"] = s.arc_radius;
        sj["arc_half_angle"] = s.arc_half_angle;
        sj["arc_offset"] = s.arc_offset;
        sj["sac_centre"] = to_j(s.sac_centre);
        sj["sac_radius"] = s.sac_radius;
        sj["neck_smoothing"] = s.neck_smoothing;
        break;
      case SynthShape::heart:
        sj["semi_axes"] = to_j(s.semi_axes);
        sj["wall_thickness"] = s.wall_thickness;
        sj["base_height"] = s.base_height;
        sj["rim_smoothing"] = s.rim_smoothing;
        sj["z_offset"] = s.z_offset;
        j["wall_label"] = kWallLabel;
        break;
    }
    j["shape_parameters"] = sj;
  }
  json rot = json::array();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rot.push_back(p.pose.rotation(r, c));
  j["similarity"] = {{"centre", to_j(p.pose.centre)},
                     {"rotation", rot},
                     {"scale", p.pose.scale},
                     {"translation", to_j(p.pose.translation)}};
  json centres = json::array(), displacements = json::array();
  for (const auto& c : p.deformation.centres) centres.push_back(to_j(c));
  for (const auto& d : p.deformation.displacements) displacements.push_back(to_j(d));
  j["deformation"] = {{"width_mm", p.deformation.width_mm}, {"centres", centres}, {"displacements", displacements}};
  j["bias_field"] = {{"strength", p.bias_field.strength},
                     {"centre", to_j(p.bias_field.centre)},
                     {"half_extent", to_j(p.bias_field.half_extent)},
                     {"coefficients", p.bias_field.coefficients}};
}

SynthParams synth_params_from_json(const nlohmann::json& j) {
  SynthParams p;
  SynthOptions& o = p.options;
  try {
    if (j.value("format", std::string()) != "mrsnake synth parameters")
      throw InputError(
          "not an mrsnake synth parameter file (no \"format\": \"mrsnake synth parameters\"); give the params.json "
          "written by 'mrsnake synth'");
    o.seed = j.at("seed").get<std::uint64_t>();
    o.size = j.at("size").get<std::array<int, 3>>();
    o.spacing = j.at("spacing").get<std::array<double, 3>>();
    o.noise = parse_synth_noise(j.at("noise").get<std::string>());
    o.snr = j.at("snr").get<double>();
    o.blur_mm = j.at("blur_mm").get<double>();
    o.bias = j.at("bias").get<double>();
    o.random_pose = j.at("pose").get<std::string>() == "random";
    o.deform_mm = j.at("deform_mm").get<double>();
    if (j.contains("source")) {
      const json& src = j.at("source");
      o.source_image = src.at("image").get<std::string>();
      o.source_labels = src.at("labels").get<std::string>();
      o.source_label = src.at("label").get<int>();
      o.source_component = src.value("component", 0);
    } else {
      o.shape = parse_synth_shape(j.at("shape").get<std::string>());
      o.foreground = j.at("foreground").get<double>();
      o.background = j.at("background").get<double>();
      o.supersampling = j.at("supersampling").get<int>();
      const json& sj = j.at("shape_parameters");
      ShapeParams& s = p.shape;
      s.kind = o.shape;
      switch (s.kind) {
        case SynthShape::sphere: s.radius = sj.at("radius").get<double>(); break;
        case SynthShape::ellipsoid: s.semi_axes = vec_from(sj.at("semi_axes")); break;
        case SynthShape::blob:
          s.base_radius = sj.at("base_radius").get<double>();
          s.bump_directions = vecs_from(sj.at("bump_directions"));
          s.bump_heights = sj.at("bump_heights").get<std::vector<double>>();
          s.bump_concentrations = sj.at("bump_concentrations").get<std::vector<double>>();
          if (s.bump_heights.size() != s.bump_directions.size() ||
              s.bump_concentrations.size() != s.bump_directions.size())
            throw InputError("params: the blob's bump lists differ in length");
          break;
        case SynthShape::aneurysm:
          s.vessel_radius = sj.at("vessel_radius").get<double>();
          s.arc_radius = sj.at("arc_radius").get<double>();
          s.arc_half_angle = sj.at("arc_half_angle").get<double>();
          s.arc_offset = sj.at("arc_offset").get<double>();
          s.sac_centre = vec_from(sj.at("sac_centre"));
          s.sac_radius = sj.at("sac_radius").get<double>();
          s.neck_smoothing = sj.at("neck_smoothing").get<double>();
          break;
        case SynthShape::heart:
          s.semi_axes = vec_from(sj.at("semi_axes"));
          s.wall_thickness = sj.at("wall_thickness").get<double>();
          s.base_height = sj.at("base_height").get<double>();
          s.rim_smoothing = sj.at("rim_smoothing").get<double>();
          s.z_offset = sj.at("z_offset").get<double>();
          break;
      }
    }
    validate(o);
    const json& sim = j.at("similarity");
    p.pose.centre = vec_from(sim.at("centre"));
    const auto rot = sim.at("rotation").get<std::vector<double>>();
    if (rot.size() != 9) throw InputError("params: similarity.rotation must hold 9 numbers (row-major 3x3)");
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) p.pose.rotation(r, c) = rot[3 * r + c];
    p.pose.scale = sim.at("scale").get<double>();
    p.pose.translation = vec_from(sim.at("translation"));
    const json& def = j.at("deformation");
    p.deformation.width_mm = def.at("width_mm").get<double>();
    p.deformation.centres = vecs_from(def.at("centres"));
    p.deformation.displacements = vecs_from(def.at("displacements"));
    if (p.deformation.centres.size() != p.deformation.displacements.size())
      throw InputError("params: deformation.centres and deformation.displacements differ in length");
    const json& b = j.at("bias_field");
    p.bias_field.strength = b.at("strength").get<double>();
    p.bias_field.centre = vec_from(b.at("centre"));
    p.bias_field.half_extent = vec_from(b.at("half_extent"));
    p.bias_field.coefficients = b.at("coefficients").get<std::array<double, 9>>();
  } catch (const nlohmann::json::exception& e) {
    throw InputError(std::string("malformed synth parameters: ") + e.what() +
                     "; give the params.json written by 'mrsnake synth'");
  }
  if (!(p.pose.scale > 0) || !(p.deformation.width_mm > 0))
    throw InputError("malformed synth parameters: similarity.scale and deformation.width_mm must be positive");
  return p;
}

}  // namespace mrsnake
