#pragma once
// DicomViewBuilder: C-arm views from the geometry tags of X-ray DICOM files, one view per file (and frame), named
// after the file, for the view file (`fluoroct views --from-dicom`, the Studio's "Views from DICOM tags").

#include <filesystem>
#include <optional>
#include <vector>

#include "Base/Result.h"
#include "IO/Dicom/XrayGeometryReader.h"
#include "IO/Project/ViewFile.h"

namespace fct {

/// Which frame to take and which geometry values to supply or replace.
struct DicomViewOptions {
  std::optional<int> frame;            ///< 0-based frame of every multi-frame file; nullopt = frame 0
  XrayGeometryOverrides overrides;     ///< SID, SOD, pixel spacing replacing or supplying the files' values
};

/// Builds views from X-ray DICOM files.
class DicomViewBuilder {
 public:
  /// One view per file, in order: name = file stem (made unique with _2, _3, ...; "_f<N>" added when a frame is
  /// chosen), image path (absolute) and frame, camera from XrayGeometryReader::frameCamera (mirror_columns set for an
  /// image stored mirrored). Fails naming the file: not an X-ray DICOM, frame out of range, a missing tag (with the
  /// view-file key that supplies it), implausible geometry. Warnings are prefixed with the file name.
  static Result<std::vector<ViewSpec>> build(const std::vector<std::filesystem::path>& files,
                                             const DicomViewOptions& options = {});
};

}  // namespace fct
