#pragma once
// LandmarkFile: CT landmarks as 3D Slicer markups JSON (.mrk.json, point list "Fiducial"), and X-ray landmarks as
// {"views": {"AP": [{"name": "L1", "uv_px": [u, v]}, ...], ...}}.

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "Base/Result.h"
#include "Geometry/Landmarks.h"

namespace fct {

/// Reads and writes landmark files.
class LandmarkFile {
 public:
  /// Reads the control points of every point list ("Fiducial") in a Slicer markups file, converted to LPS mm
  /// (a "RAS" list has x and y negated; "um" units are scaled to mm). Other markup types and points with
  /// positionStatus "undefined" are skipped with a warning. Fails naming the file and landmark on a missing
  /// position, NaN, an empty or duplicate label, or an unknown coordinate system.
  static Result<std::vector<CtLandmark>> readCt(const std::filesystem::path& path);

  /// Writes CT landmarks (LPS mm) atomically as a Slicer markups point list in LPS that Slicer opens as is.
  /// Fails on empty or duplicate names, non-finite positions, or an unwritable path.
  static Status writeCt(const std::vector<CtLandmark>& landmarks, const std::filesystem::path& path);

  /// Reads X-ray landmarks per view name (pixels, (col,row)). Fails naming the file, view and landmark on a
  /// missing uv_px, NaN, or an empty or duplicate name within a view.
  static Result<std::map<std::string, std::vector<ImageLandmark>>> readImage(const std::filesystem::path& path);

  /// Writes X-ray landmarks per view atomically. Fails on empty or duplicate names within a view, non-finite
  /// coordinates, or an unwritable path.
  static Status writeImage(const std::map<std::string, std::vector<ImageLandmark>>& landmarksByView,
                           const std::filesystem::path& path);
};

}  // namespace fct
