#pragma once
// DicomRegistrationWriter: writes the bone pose as a DICOM Spatial Registration object (SOP class
// 1.2.840.10008.5.1.4.1.1.66.1, modality REG; PS3.3 A.39) with DCMTK. The registration's own Frame of Reference is
// the C-arm world; the Registration Sequence holds an item for the CT's Frame of Reference with T_world_from_ct as
// its RIGID Frame of Reference Transformation Matrix (it maps CT patient coordinates into the world, PS3.3 C.20.2)
// and an item for the world's Frame of Reference with the identity. Read back with DicomRegistrationReader.

#include <filesystem>
#include <vector>

#include "Base/Result.h"
#include "Image/Volume.h"
#include "IO/Dicom/DicomRegistration.h"

namespace fct {

/// Writes DICOM Spatial Registration objects.
class DicomRegistrationWriter {
 public:
  /// The registration of `ct` by `T_world_from_ct` (LPS mm) to the world of the X-ray files. Patient, study, series,
  /// Frame of Reference and slices come from the CT's DICOM identity; a CT not read from DICOM gets a generated Frame
  /// of Reference UID and a new study, said in a warning. The X-ray DICOM files (the views' images that are DICOM)
  /// are referenced and lend the world their common Frame of Reference UID (a new UID otherwise, with a warning when
  /// they disagree). Fails when an X-ray DICOM file cannot be read or the pose is not rigid.
  static Result<DicomRegistration> describe(const Volume& ct, const Eigen::Isometry3d& T_world_from_ct,
                                            const std::vector<std::filesystem::path>& xrayDicomFiles);

  /// Writes the REG object to `path` atomically (temporary file, then rename): patient, study, series, frame of
  /// reference, equipment, spatial registration, common instance reference and SOP common modules. Generates the
  /// SOP instance and series UIDs when empty. Fails on a missing CT or world Frame of Reference UID, a non-rigid
  /// matrix, or an unwritable path; an existing file at `path` is then left as it was.
  static Status write(const DicomRegistration& registration, const std::filesystem::path& path);
};

}  // namespace fct
