#pragma once
// RegistrationSchedule: the registration pipeline as data: an ordered list of stages, each naming a similarity
// metric, a pyramid level, the pixel set compared and the search strategy with its options. The built-in presets
// ("paper", "fast") are the JSON files of Resources/presets, embedded into the binary at build time; a user file
// with the same schema is loaded the same way (README "Registration presets" documents the keys).
//
// Ablation switches turn one technique of the paper off at a time (withAblation), so its effect can be measured.

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "Base/Result.h"
#include "Drr/DrrRendererFactory.h"
#include "Search/CmaEsOptimizer.h"
#include "Search/GeneticSearchOptimizer.h"
#include "Search/LocalPoseOptimizer.h"
#include "Similarity/VlncSimilarity.h"

namespace fct {

/// The similarity of a stage (per view; the objective is over all views).
enum class SimilarityMetric { Ncc, Vlnc, GradientCorrelation };
/// Which pixels of each view a stage compares.
enum class PixelSetKind {
  WholeImage,  ///< every valid pixel (NCC, GC); for VLNC every complete valid w x w window
  Rois,        ///< the dynamic ROIs: the highest-variance w x w windows covering a target fraction of valid pixels
};
/// The search strategy of a stage.
enum class SearchStrategy { Genetic, CmaEs, Local };
/// Where a VLNC stage's window weights come from.
enum class VlncWeightSource {
  Xray,  ///< each window's X-ray variance (the paper's)
  Drr,   ///< each window's variance in a DRR at the stage's start (RegistrationCase::weighWindowsWithDrr)
};

/// The pixel set of a stage.
struct PixelSetSpec {
  PixelSetKind kind = PixelSetKind::WholeImage;
  int windowSize = 7;            ///< w, pixels of the stage's level (ROIs, and VLNC windows of a whole image)
  double targetFraction = 0.12;  ///< ROIs: fraction of the valid pixels kept (0 < f <= 1; the paper: 0.10-0.15)
  /// Whole-image NCC/GC sets: at most this many pixels per view, by keeping every k-th column and row (k as small as
  /// fits); 0 = no cap. A large detector's coarse level then costs like a small one's (VLNC and ROI sets ignore it).
  int maxPixels = 0;
};

/// A stage's rotation sweep before its search (RotationSweep): none unless maxRotation_deg > 0.
struct RotationSweepSpec {
  double maxRotation_deg = 0.0;  ///< radius of the grid of rotation vectors, deg; 0 = no sweep
  double step_deg = 20.0;        ///< grid spacing per axis, deg
  int aligned = 8;               ///< the best grid poses that are shift-aligned and ranked again
  int seeds = 2;                 ///< at most this many poses that beat the start go to the search
  int maxPixels = 625;           ///< whole-image pixels per view that rank the grid (the stage's own set ranks the rest)
};

/// One stage of the schedule. Option units follow the optimizers: scaled units (about 1 mm of bone-surface motion),
/// except the genetic spreads (deg, mm). The genetic drop threshold is in similarity units (mean over views).
struct RegistrationStage {
  std::string name;
  SimilarityMetric metric = SimilarityMetric::Ncc;
  int level = 0;                   ///< pyramid level: 0 = full resolution, 2 = 1:16 pixels
  /// VLNC: compare line integrals (the paper's) or detector intensities (invariant to a scatter haze; JSON "domain").
  VlncDomain vlncDomain = VlncDomain::LineIntegral;
  /// Render with the case's exact renderer even when it has per-view Transgraphs (whose interpolation smooths detail
  /// finer than the table spacing: measured too coarse for the full-resolution stage, see README).
  bool exactDrr = false;
  /// Render this stage exactly with this method ("siddon" or "raycast") whatever the case's method (the Transgraph is
  /// then not used either); nullopt: the case's renderers. Trilinear sampling ("raycast") models a smooth patient where
  /// exact box voxels show the CT's staircase (docs/evaluation.md, "Start at the truth").
  std::optional<DrrMethod> drrMethod;
  /// With drrMethod raycast: the sampling step in voxels (one voxel: the cube root of the voxel volume); 0: the
  /// renderer's default, half the smallest spacing.
  double drrStep_voxels = 0.0;
  /// With drrMethod raycast: what a CT slice's value stands for (JSON "drr_slices": "samples" or "slab_averages").
  /// Slab averages render a CT of thick slices deconvolved along them, its slab edges then no longer blurred over two
  /// slices (DrrVolume::sliceAveragesDeconvolved; a near-cubic grid stays samples; docs/evaluation.md, "Slice profile").
  CtSliceModel drrSlices = CtSliceModel::Samples;
  /// Before the search, move the start by the translation that lines up each view's DRR with its X-ray in 2D at the
  /// stage's level (ProjectionShiftAligner), when that raises the stage's similarity: a far start's DRR then overlaps
  /// its X-ray before the search looks around it.
  bool shiftPrealign = false;
  /// Before the stage, give back the metal-mask pieces that a DRR at the stage's start explains (anatomy taken for
  /// metal, RegistrationCase::reviewMetalMasks); for a stage that starts near the truth, after the global search.
  bool metalReview = false;
  /// Before the stage (after the metal review), remove a smooth haze of this Gaussian sigma on the detector (mm) from
  /// every X-ray with a DRR at the stage's start (RegistrationCase::removeHaze); the stages after it compare the
  /// corrected X-rays too. 0: off. For a stage that starts near the truth (JSON "haze_sigma_mm").
  double hazeSigma_mm = 0.0;
  /// VLNC: weigh each window by its variance in the X-ray (the paper's) or in a DRR rendered at the stage's start
  /// (after the haze removal). Noise-free, the DRR weighs a window by the structure the CT predicts there, not by the
  /// X-ray's noise (JSON "weights": "xray" or "drr"; docs/evaluation.md, "Window weights").
  VlncWeightSource vlncWeights = VlncWeightSource::Xray;
  /// Before the search (after the shift pre-alignment), look around the start's rotation on a coarse grid; the poses
  /// that beat the start are refined beside it (genetic) or replace it (local, CMA-ES: the best one).
  RotationSweepSpec rotationSweep;
  PixelSetSpec pixels;
  SearchStrategy search = SearchStrategy::Local;
  int maxEvaluations = 1000;       ///< cap on DRR sets (one per view) of the stage's search
  GeneticSearchOptions genetic;    ///< used by Genetic (its `local` is the simplex below)
  CmaEsOptions cmaes;              ///< used by CmaEs
  LocalSearchOptions simplex;      ///< the local search (simplex or BOBYQA): alone (Local) or inside each genetic guess
  /// Local search with one view: > 1 searches the translation across and along the viewing ray (source to the bone
  /// centre at the stage's start), with the scaled unit along the ray this many times the unit across it. One view
  /// sees that depth only through the magnification, so the similarity is far flatter along it and a search in equal
  /// units stops before it moves the depth (docs/tracking.md). 1: the world axes in equal units. JSON
  /// "search": "depth_scale".
  double depthScale = 1.0;
};

/// Ablation switches: each one true turns a technique of the paper off (defaults: everything on). The five techniques
/// of the paper are dynamic ROIs, the pyramid, the Transgraph, NCC -> VLNC and the genetic search (localOnly);
/// noTransgraph acts on the case's renderers (Registration), the others on the stages (withAblation).
struct RegistrationAblation {
  bool noDynamicRois = false;      ///< ROIs -> every valid pixel (VLNC: every complete window)
  bool noPyramid = false;          ///< every stage at level 0
  bool nccOnly = false;            ///< NCC in every stage (no switch to VLNC)
  bool localOnly = false;          ///< every global search replaced by the local simplex
  bool cmaesForGenetic = false;    ///< CMA-ES wherever the schedule says genetic
  bool noTransgraph = false;       ///< exact (Siddon) DRRs instead of the per-view Transgraphs (transgraph method)
  bool noCtPyramid = false;        ///< exact DRRs of every level integrate the full CT (not one coarsened to the level)

  /// Names of the switches that are on, for reports ("no-rois", "no-pyramid", ...).
  std::vector<std::string> activeNames() const;
};

/// An ordered list of registration stages.
class RegistrationSchedule {
 public:
  /// The preset the programs use unless told otherwise: "clinical" (the paper's accuracy at a tenth of its time).
  static constexpr const char* kDefaultPreset = "clinical";
  /// Names of the built-in presets, e.g. {"clinical", "fast", "paper"}.
  static std::vector<std::string> builtinNames();
  /// A built-in preset by name; the error lists the names.
  static Result<RegistrationSchedule> builtin(std::string_view name);
  /// Reads a schedule file (JSON, schema of the built-in presets); the error names the file, stage and key.
  static Result<RegistrationSchedule> readFile(const std::filesystem::path& path);
  /// A built-in preset when `nameOrPath` is one of builtinNames(), else readFile(nameOrPath).
  static Result<RegistrationSchedule> resolve(const std::string& nameOrPath);
  /// Parses a schedule from JSON; `where` names the source in messages. Fails on a missing or bad key, no stage,
  /// a level outside 0..7, a window outside 2..64, a fraction outside (0, 1], or invalid optimizer options.
  static Result<RegistrationSchedule> fromJson(const nlohmann::json& document, const std::string& where);

  /// The schedule in the JSON schema fromJson() reads (a round trip gives an equal schedule).
  nlohmann::ordered_json toJson() const;
  /// One line per stage that names its own DRR method, for reports: "stage 'S' renders its DRRs with the raycast
  /// method (a sample every 1 voxel)". Empty when every stage uses the case's renderers.
  std::vector<std::string> stageDrrNotes() const;
  /// This schedule with the given techniques switched off (see RegistrationAblation); the name gets a suffix.
  RegistrationSchedule withAblation(const RegistrationAblation& ablation) const;
  /// This schedule with every stage's random seed derived from `seed` (stage i gets seed + i).
  RegistrationSchedule withSeed(std::uint32_t seed) const;
  /// This schedule with every ROI stage's window size and target fraction replaced (e.g. by the user's tuning);
  /// stages on whole images are unchanged. Fails on a window outside 2..64 or a fraction outside (0, 1].
  Result<RegistrationSchedule> withRoiPixels(int windowSize, double targetFraction) const;

  /// Lowercase name of a metric ("ncc", "vlnc", "gc").
  static std::string_view metricName(SimilarityMetric metric);
  /// Lowercase name of a strategy ("genetic", "cmaes", "local").
  static std::string_view searchName(SearchStrategy search);
  /// The metric of a metricName(); fails naming the text and the accepted names.
  static Result<SimilarityMetric> parseMetric(std::string_view name);
  /// The strategy of a searchName(); fails naming the text and the accepted names.
  static Result<SearchStrategy> parseSearch(std::string_view name);

  std::string name;
  std::string description;
  std::vector<RegistrationStage> stages;
};

}  // namespace fct
