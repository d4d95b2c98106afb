#pragma once
/// \file segment.h
/// The coarse-to-fine segmentation: normalize the image and build its pyramid, place the
/// coarse mesh (model pose, moments of a rough threshold, fit to the search targets), then
/// for each level j deform S_j on the matching pyramid level and synthesize S_{j+1} from the
/// deformed S_j with the model's details. The connectivity never changes.
#include <functional>
#include <memory>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "mesh/progress.h"
#include "mesh/subdivision.h"
#include "mesh/trimesh.h"
#include "mesh/volume.h"
#include "snake/appearance.h"
#include "snake/deformable_surface.h"
#include "snake/image_pyramid.h"
#include "snake/initialize.h"

namespace mrsnake {

/// What the segmentation needs from a shape model.
struct SnakeModel {
  SubdivisionConnectivity connectivity;
  std::vector<RowMatrixX3d> levels;  ///< S_0..S_L in the model's physical pose
  /// S_{j+1} from a (deformed) S_j, j = 0..L−1, with the model's stored details.
  std::function<RowMatrixX3d(int j, const RowMatrixX3d& coarse)> synthesize;
  std::optional<Appearance> appearance;
  /// The normalized crop of the reference image (snake/reference_image.h), if stored.
  std::optional<Volume> reference_image;

  int finest_level() const { return connectivity.levels(); }
  const RowMatrixX3i& faces(int j) const { return connectivity.faces[j]; }
};

enum class InitMode {
  automatic,        ///< register+fit when the model has a reference image, else moments+fit (default)
  pose,             ///< the model's physical pose as is
  moments,          ///< + moments of a rough threshold
  moments_and_fit,  ///< + a similarity fit of the coarse mesh to its search targets (also tried from the model's pose)
  fit,              ///< the model's pose + the fit
  registration,     ///< + registration of the model's reference image to the image
  registration_and_fit,  ///< + the registration, then the fit
};
/// \throw InputError for an unknown name (auto, pose, moments, moments+fit, fit, register, register+fit).
InitMode parse_init_mode(const std::string& name);
std::string to_string(InitMode mode);

enum class ForceMode { automatic, profile, step_edge };
/// \throw InputError for an unknown name (auto, profile, edge).
ForceMode parse_force_mode(const std::string& name);
std::string to_string(ForceMode mode);

/// How a level finer than the image is deformed (SegmentOptions::fine).
struct FineLevelOptions {
  bool deform_edge_centred = true;  ///< false: only synthesize every level finer than min_edge_voxels
  /// Levels whose mean edge is below this many voxels of the image are never deformed: the
  /// profiles' centring was decided on the reference image's grid, and on a coarser image
  /// they no longer resolve such a level.
  double min_edge_voxels = 0.5;
  /// Standard deviation, in voxels of the full-resolution image, of the ring averaging of the
  /// matched offsets: k passes of the 7-point average on a regular mesh of edge e spread a
  /// value with a variance of k·(3/7)·e² per axis. On the five synthetic heart 128³ cases
  /// (finest edges 1.0 voxel), 1.3 / 1.6 / 1.85 / 2.3 / 2.9 voxels gave a mean Dice of
  /// 0.99084 / 0.9910 / 0.99106 / 0.99108 / 0.99104: 1.85 is the knee of the mean. At SNR 2
  /// alone the Dice kept rising, 0.9860 to 0.9880.
  double offset_smoothing_voxels = 1.85;
  /// The level starts within a voxel: it may stop after min_iterations (at most
  /// SnakeOptions::min_iterations), once the offsets and the energy have settled over
  /// patience iterations (at most SnakeOptions::patience).
  int min_iterations = 2;
  int patience = 2;
  /// Profile search step, as a fraction of the profile spacing (SegmentOptions has 0.5):
  /// after the averaging, the half steps changed the five synthetic hearts' mean Dice by 0.0001
  /// and took twice the time. (The snake's settling tolerance is relative to this step, so it
  /// is twice as loose too.)
  double profile_step_fraction = 1.0;
};

/// The most iterations a level may run: snake.max_iterations and --max-iterations.
constexpr int kMaxSnakeIterations = 100000;

struct SegmentOptions {
  SnakeOptions snake;
  InitMode init = InitMode::automatic;
  /// The registration routes; when the registration is rejected they fall back to the
  /// moments routes (register → moments, register+fit → moments+fit).
  ReferenceRegistrationOptions registration;
  /// automatic: profile when the model has an appearance whose profiles are not a clean step
  /// (profile_step_residual above clean_step_max_residual), else step_edge.
  ForceMode force = ForceMode::automatic;
  double clean_step_max_residual = 0.2;
  TargetFitOptions fit;
  /// The fit stops when its mean vertex motion falls below this many voxels of the image
  /// (its tolerance_mm is set from it).
  double fit_tolerance_voxels = 0.01;
  /// After an accepted registration the fit only refines: it keeps its best-matching pose and
  /// stops after this many iterations without a better one (TargetFitOptions::patience).
  /// Across mice the fit ran its 30 iterations on 5 of 6 structures while its matches got
  /// worse (the superior colliculi shrank to 0.54 of their volume, Dice 0.88 → 0.68); on the
  /// warped same-subject cases it changed the mean Dice by −0.0002. (From the moments, where
  /// the fit does the search, its cost is no guide on the way in: the synthetic aneurysm
  /// fell from 0.954 to 0.949 with it.)
  int fit_patience_after_registration = 3;
  int fit_level = 2;  ///< the mesh level whose vertices the similarity fit uses (capped at L)
  MomentsOptions moments;
  /// Search range at level j: max(min_range_voxels·voxel, range_edge_fraction·edge_j); the
  /// coarsest level uses coarse_range_edge_fraction for the initial fit.
  double range_edge_fraction = 0.5;
  double coarse_range_edge_fraction = 0.75;
  double min_range_voxels = 1.0;       ///< levels: the search range is at least this many voxels
  double fit_min_range_voxels = 4.0;   ///< the initial fit's search range is at least this many voxels
  double step_voxels = 0.5;            ///< search step, in voxels of the pyramid level
  double profile_step_fraction = 0.5;  ///< profile search step, as a fraction of the profile spacing
  /// The search range is at most this many voxels of the pyramid level (0: no cap), on the
  /// levels and in the initial fit.
  double max_range_voxels = 0;
  double window_voxels = 2.0;     ///< step_edge half window, in voxels of the pyramid level
  double edge_per_voxel = 2.0;    ///< pyramid level choice (appearance.h)
  double max_edge_cost = 0.35;    ///< step-edge matches worse than this are ignored (forces.h)
  double max_profile_cost = 0.4;  ///< profile matches with a correlation below 0.6 are ignored
  /// NormalSearchOptions::distance_penalty per force, and ::min_gain (forces.h). Measured
  /// with bench_snake_levels (profile force) on 10 synthetic blob/heart cases and 4 real ones
  /// (liver, 4th ventricle, hippocampi): 0.05 lost up to 0.0024 Dice against the best (heart
  /// SNR 2); 0.02 with external_weight 0.35 lost at most
  /// 0.0015 (liver) and raised the mean; more damping (0.15, or any min_gain) lost more. The
  /// step-edge force keeps 0.05: at 0.02 the aneurysm end-to-end case fell from 0.954 to 0.949.
  double profile_distance_penalty = 0.02;
  double edge_distance_penalty = 0.05;
  double search_min_gain = 0.0;
  /// Search evidence shared with the 1-ring (NormalSearchOptions::ring_weight): a vertex
  /// whose own best cost is c mixes in its ring's cost curves with weight
  /// ring_weight·min(1, c/ring_full_weight_cost). On the 10 quick synthetic cases it raised the
  /// SNR 2 heart's Dice from 0.9822 to 0.9844 and the mean from 0.99133 to 0.99161; a weight
  /// that ignores the vertex's own cost (0.85 everywhere) lost up to 0.005 on real MRI.
  double cost_ring_weight = 0.85;
  double cost_ring_full_weight_cost = 0.2;
  /// Voxels (on a regular stride) from which the robust intensity window is estimated: a
  /// quarter of the default 2^20 takes a few ms instead of ~15 ms at 128³ and 256³ and moves
  /// the 1st and 99th percentiles by well under 1% of the window (tests/snake).
  std::size_t intensity_samples = std::size_t{1} << 18;
  bool count_self_intersections = true;
  /// After each level, move the vertices of self-intersecting faces back towards the
  /// level's start (deformable_surface.h).
  bool undo_self_intersections = true;
  /// With the profile force, levels whose mean edge (on the model) is below this many voxels
  /// of the image are only synthesized, not deformed (0: deform every level), unless their
  /// profiles are centred on the image's edges (`fine`, below). On the real
  /// images their snake lost Dice (e.g. the CT liver's finest level). 1.25, not 1: the synthetic
  /// heart models' finest edges are 0.998-1.000 voxel, so at 1 a 0.2 % change in the model
  /// (the remesher's surface fit) decided whether that level ran: 70 ms more and Dice -0.001.
  double min_edge_voxels = 1.25;
  /// Levels finer than min_edge_voxels whose profiles are centred on the image's edges
  /// (LevelAppearance::centre) are deformed after all: such profiles locate the
  /// object's boundary below the label's rounding. Each matched offset is close to the
  /// voxel's noise there, so the offsets are averaged over rings until the averaging reaches
  /// fine.offset_smoothing_voxels, and the level starts within a voxel, so it may stop sooner.
  /// (With the labels' profiles, deforming the real cases' finer levels lost Dice even with
  /// that averaging: the left hippocampus 0.9531 → 0.9505.)
  FineLevelOptions fine;
};

struct LevelOutcome {
  int level = 0;
  int pyramid_level = 0;
  double voxel_mm = 0;
  double range_mm = 0;
  int vertices = 0;
  SnakeLevelReport snake;
  int rolled_back_vertices = 0;  ///< vertices moved back to undo self-intersections
  bool deformed = true;  ///< false: finer than the image (min_edge_voxels) and not deformed as such (FineLevelOptions),
                         ///< only synthesized
  int offset_smoothing = 0;  ///< ring-averaging passes over the matched offsets (SnakeOptions)
  double seconds = 0;        ///< synthesis + snake of this level
  double synthesis_seconds = 0;
  TriMesh surface;  ///< S_j after deformation
};

struct SegmentResult {
  TriMesh surface;  ///< the final level
  std::vector<LevelOutcome> levels;
  Similarity initial_pose;                            ///< applied to the model's S_0 before the coarse-to-fine run
  InitMode init = InitMode::pose;                     ///< the route taken (auto resolved, after any fallback)
  std::optional<ReferenceRegistration> registration;  ///< when a registration route was asked for
  int fit_iterations = 0;
  /// The start the fit kept: "registration", "moments", "moments without rotation" or
  /// "model pose"; empty without a fit.
  std::string fit_start;
  RegionStats region;
  IntensityWindow window;
  int self_intersections = -1;  ///< -1 when not counted
  std::string force;            ///< "profile" or "step_edge"
  /// profile_step_residual of the model's appearance (appearance.h) when the force was
  /// chosen automatically; +infinity otherwise.
  double profile_step_residual = std::numeric_limits<double>::infinity();
  /// The match at the end against chance (match_evidence in segment.cpp): the mean best cost
  /// of the last deformed level's search on its final surface, and on that surface moved off
  /// by its equivalent radius along each axis, both ways (where the image holds nothing of
  /// the structure). NaN when no level was deformed.
  double final_match_cost = std::numeric_limits<double>::quiet_NaN();
  double chance_match_cost = std::numeric_limits<double>::quiet_NaN();
  /// With an accepted registration: the normalized cross-correlation of the reference crop
  /// with the new image where the registration puts it, both at twice the registered pyramid
  /// level's voxel (so that the voxels' noise is averaged out): whether the image looks like
  /// the reference, whatever the metric or the intensities' scale. The same for every
  /// structure that shares the crop. (Over each structure's own box it varied too much: the
  /// small, faint structures of the mice fell to 0.47.) NaN otherwise.
  double registration_correlation = std::numeric_limits<double>::quiet_NaN();
  /// Why the initialization asked for failed, when the caller fell back on the model's own
  /// pose (segment_case does, so that one structure cannot stop the others); empty otherwise.
  std::string initialization_failure;
  std::vector<std::pair<std::string, double>> stage_seconds;
  double compute_seconds = 0;  ///< everything after loading, without the final self-intersection count
};

/// The snake options of a level deformed although finer than the image (FineLevelOptions):
/// options.snake with the offsets averaged over rings until their spread reaches
/// fine.offset_smoothing_voxels (edge_voxels: the level's mean edge in voxels of the image),
/// and the fine level's iteration limits.
/// \pre edge_voxels > 0 (otherwise the averaging is left as in options.snake).
/// \throw nothing.
SnakeOptions fine_level_snake_options(const SegmentOptions& options, double edge_voxels);
/// The same from the level's snake options and the fine levels' settings.
SnakeOptions fine_level_snake_options(const SnakeOptions& snake, const FineLevelOptions& fine, double edge_voxels);

// SegmentOptions as JSON (mesh/json_options.h: `segment --config FILE`, report.json's
// "options"); docs/segmentation.md lists every key. Enums are their command-line names
// (--init, --force, --register-metric); a name that is none of them is an InputError.
// Left out, because the segmentation sets them itself: TargetFitOptions::tolerance_mm (from
// fit_tolerance_voxels), RegistrationOptions::initial_translation and
// ::moving_intensity_scale/offset (from the start and the image's normalization).
inline void to_json(nlohmann::json& j, InitMode m) { j = to_string(m); }
inline void from_json(const nlohmann::json& j, InitMode& m) { m = parse_init_mode(j.get<std::string>()); }
inline void to_json(nlohmann::json& j, ForceMode m) { j = to_string(m); }
inline void from_json(const nlohmann::json& j, ForceMode& m) { m = parse_force_mode(j.get<std::string>()); }
inline void to_json(nlohmann::json& j, RegistrationMetric m) { j = to_string(m); }
inline void from_json(const nlohmann::json& j, RegistrationMetric& m) {
  m = parse_registration_metric(j.get<std::string>());
}
// MomentsOptions::threshold's NaN (Otsu's threshold) is null.
void to_json(nlohmann::json& j, const MomentsOptions& o);
void from_json(const nlohmann::json& j, MomentsOptions& o);
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(SnakeOptions, membrane_weight, thin_plate_weight, prior_weight,
                                                tangential_weight, external_weight, time_step, max_step_fraction,
                                                offset_median, offset_smoothing, max_iterations, min_iterations,
                                                tolerance, patience)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(TargetFitOptions, iterations, with_scale, trim_fraction, patience)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(RegistrationOptions, metric, histogram_bins, shrink_factors,
                                                smoothing_voxels, samples_per_level, iterations_per_level,
                                                evaluation_samples, initial_step_voxels, rotation_radius_mm,
                                                step_factor_per_level, min_step_voxels, relaxation, min_relative_change,
                                                convergence_window, moving_margin_fraction, moving_margin_voxels,
                                                max_seconds, threads)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(ReferenceRegistrationOptions, itk, min_scale, max_scale)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(FineLevelOptions, deform_edge_centred, min_edge_voxels,
                                                offset_smoothing_voxels, min_iterations, patience,
                                                profile_step_fraction)
NLOHMANN_DEFINE_TYPE_NON_INTRUSIVE_WITH_DEFAULT(
    SegmentOptions, snake, init, registration, force, clean_step_max_residual, fit, fit_tolerance_voxels,
    fit_patience_after_registration, fit_level, moments, range_edge_fraction, coarse_range_edge_fraction,
    min_range_voxels, fit_min_range_voxels, step_voxels, profile_step_fraction, max_range_voxels, window_voxels,
    edge_per_voxel, max_edge_cost, max_profile_cost, profile_distance_penalty, edge_distance_penalty, search_min_gain,
    cost_ring_weight, cost_ring_full_weight_cost, intensity_samples, count_self_intersections, undo_self_intersections,
    min_edge_voxels, fine)

/// Refuses options out of their range, by their options-file keys ("snake.max_iterations"):
/// segment() and the commands call it before any work.
/// \throw OptionsError naming the first such option.
void check_options(const SegmentOptions& options);

/// Segments `image` (any spacing and direction; not modified) with the model.
/// \throw InputError if the model has no levels or its appearance does not match it, or if
///        options ask for --init register without a reference image in the model.
/// \throw AlgorithmError if the initialization finds nothing to align to.
/// \throw OptionsError if an option is out of its range (check_options).
SegmentResult segment(const Volume& image, const SnakeModel& model, const SegmentOptions& options = {},
                      const ProgressFn& progress = {});

/// The image side of a segmentation: the robust intensity window and the normalized pyramid,
/// made once and shared by every structure of a model.
struct SegmentationImage {
  IntensityWindow window;
  std::unique_ptr<NormalizedPyramid> pyramid;
  std::vector<std::pair<std::string, double>> stage_seconds;  ///< normalize, pyramid
  double seconds = 0;
};

/// \pre image outlives the result (pyramid level 0 may be the image itself).
/// \throw OptionsError if an option is out of its range (check_options).
SegmentationImage prepare_segmentation_image(const Volume& image, const SegmentOptions& options = {},
                                             const ProgressFn& progress = {});

/// The registration of `model`'s reference image to the prepared image, run once for every
/// structure that shares that reference (segment() with `registration`), when the options'
/// route registers; std::nullopt otherwise.
/// \throw InputError if the route registers and the model has no reference image.
std::optional<ReferenceRegistration> register_structures(const SegmentationImage& image, const SnakeModel& model,
                                                         const SegmentOptions& options,
                                                         const ProgressFn& progress = {});

/// segment() on a prepared image. With `registration` (from register_structures), a route
/// that registers uses it instead of registering again; its seconds are counted once, by the
/// caller. The result's compute_seconds and stage_seconds cover this structure only.
/// \throw as segment().
SegmentResult segment(const SegmentationImage& image, const SnakeModel& model, const SegmentOptions& options,
                      const ProgressFn& progress = {}, const ReferenceRegistration* registration = nullptr);

/// The report of `mrsnake segment` (timings per stage and level, iterations, convergence,
/// final energy, self-intersection count).
nlohmann::json segment_report(const SegmentResult& result);

}  // namespace mrsnake
