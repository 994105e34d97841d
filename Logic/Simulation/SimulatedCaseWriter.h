#pragma once
// SimulatedCaseWriter: writes a simulated registration case folder — one 16-bit PNG per view, the view file, the
// true pose and the simulation parameters (plus optional extra 2D float images such as distortion fields) — the
// common output of DrrXraySimulator and FluoroscopySimulator. Every file is written atomically.

#include <Eigen/Geometry>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Image/FloatImage.h"
#include "IO/Project/ViewFile.h"

namespace fct {

/// What a simulation wrote.
struct SimulatedCase {
  std::vector<ViewSpec> views;           ///< the input views with imagePath set to the written PNGs (absolute)
  std::filesystem::path viewFile;        ///< DIR/views.json
  std::filesystem::path poseFile;        ///< DIR/truth_pose.json
  std::filesystem::path parameterFile;   ///< DIR/simulation.json
  std::vector<double> maxLineIntegral;   ///< per view: the largest line integral p = -ln(I / I0) of its noiseless image
};

/// An extra 2D float image written into the case folder: float NRRD (e.g. a view's distortion field), or a 16-bit PNG
/// like the views' when the name ends in .png (e.g. a grid plate image).
struct SimulatedExtraImage {
  std::string fileName;                                   ///< file name inside the case folder, ending in .nrrd or .png
  FloatImage image;                                       ///< the values
  Eigen::Vector2d pixelSpacing_mm{1.0, 1.0};              ///< written as the NRRD spacings
};

/// Writes simulated cases.
class SimulatedCaseWriter {
 public:
  /// Checks that there is at least one view and that every view name can name a file on every platform (letters,
  /// digits, '-', '_', '.', not starting with '.'). Returns the error naming the bad view otherwise.
  static Status checkViews(const std::vector<ViewSpec>& views);

  /// Writes into `outDir` (created if missing): <view>.png (16-bit, the image's values rounded and clamped to
  /// 0..65535, MONOCHROME2), the extra images, views.json (the views with their image paths and without any input
  /// view's dewarp file, which does not describe simulated images), truth_pose.json
  /// (T_world_from_ct) and simulation.json (`parameters` after the keys views, pose and T_world_from_ct). Returns
  /// the written case with maxLineIntegral empty (the caller fills it). Fails on a view/image count mismatch, bad
  /// view names, or an unwritable folder or file.
  static Result<SimulatedCase> write(const std::vector<ViewSpec>& views, const std::vector<FloatImage>& images,
                                     const std::vector<SimulatedExtraImage>& extraImages,
                                     const Eigen::Isometry3d& T_world_from_ct, const nlohmann::ordered_json& parameters,
                                     const std::filesystem::path& outDir);
};

}  // namespace fct
