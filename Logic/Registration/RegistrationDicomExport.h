#pragma once
// RegistrationDicomExport: a registration result as a DICOM Spatial Registration object (DicomRegistrationWriter)
// referring to the CT and to the views' DICOM X-rays. The one export of the CLI (`register --dicom-reg`) and the
// Studio (Review step, "Export DICOM registration").

#include <filesystem>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"
#include "Registration/Registration.h"
#include "Registration/RegistrationView.h"

namespace fct {

/// Exports registration results as DICOM REG objects.
class RegistrationDicomExport {
 public:
  /// Writes `result.T_world_from_ct` of `ct` to `path` atomically, referencing the CT (its DICOM identity) and the
  /// views whose X-ray came from a DICOM file; the content description names the final similarity (and a cancelled
  /// run). Warnings (e.g. the generated Frame of Reference UID of a CT not read from DICOM) are on the Result.
  /// Fails on an unreadable X-ray DICOM, a non-rigid pose or an unwritable path, leaving `path` as it was.
  static Result<std::filesystem::path> write(const Volume& ct, const std::vector<RegistrationView>& views,
                                             const RegistrationResult& result, const std::filesystem::path& path);
};

}  // namespace fct
