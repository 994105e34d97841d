#pragma once
// LandmarkPairFile: a landmark pair set, the input of `fluoroct register --landmarks`:
//   {"ct": "points.mrk.json", "image": "clicks.json", "method": "reprojection"}
// naming a CT landmark file and an X-ray landmark file (LandmarkFile), relative to the pair file's folder or absolute,
// and how the initial pose is estimated from the pairs ("reprojection", the default, or "triangulation").

#include <filesystem>
#include <string_view>

#include "Base/Result.h"
#include "Geometry/Landmarks.h"

namespace fct {

/// How an initial pose is estimated from landmark pairs (LandmarkPoseEstimator::fromReprojection / fromTriangulation).
enum class LandmarkPoseMethod { Reprojection, Triangulation };

/// A landmark pair set: CT landmarks, their X-ray partners per view, the files they are kept in and the method.
struct LandmarkPairSet {
  std::filesystem::path ctFile;     ///< the CT landmark file; relative paths are relative to the pair file's folder
  std::filesystem::path imageFile;  ///< the X-ray landmark file; likewise
  LandmarkPoseMethod method = LandmarkPoseMethod::Reprojection;
  Landmarks landmarks;
};

/// Reads and writes landmark pair files.
class LandmarkPairFile {
 public:
  /// Reads the pair file and the two landmark files it names; ctFile and imageFile come back resolved against the
  /// pair file's folder. Fails naming the file and key on bad JSON, a missing or empty "ct" or "image", an unknown
  /// "method", or as LandmarkFile::readCt / readImage. Unknown keys and the landmark files' warnings are warnings.
  static Result<LandmarkPairSet> read(const std::filesystem::path& path);

  /// Writes the CT landmarks to ctFile and the X-ray landmarks to imageFile (LandmarkFile, each atomically), then the
  /// pair file at `path` naming them as given. Fails on an empty file name, as LandmarkFile::writeCt / writeImage,
  /// or on an unwritable path; the pair file is written only when both landmark files are.
  static Status write(const LandmarkPairSet& set, const std::filesystem::path& path);

  /// The method's name in the file ("reprojection", "triangulation").
  static std::string_view methodName(LandmarkPoseMethod method);
};

}  // namespace fct
