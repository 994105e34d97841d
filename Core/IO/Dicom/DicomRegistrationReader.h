#pragma once
// DicomRegistrationReader: reads a DICOM Spatial Registration object (modality REG) written by
// DicomRegistrationWriter or another system: the rigid matrix that maps the CT's Frame of Reference into the
// registration's frame.

#include <filesystem>

#include "Base/Result.h"
#include "IO/Dicom/DicomRegistration.h"

namespace fct {

/// Reads DICOM Spatial Registration objects.
class DicomRegistrationReader {
 public:
  /// The registration: world = the object's Frame of Reference UID (0020,0052); T_world_from_ct = the matrix of the
  /// first Registration Sequence item whose Frame of Reference differs from it (the product of its Matrix Sequence);
  /// patient and study into `ct`; the world item's referenced images into `xrays`. Fails naming the file and the
  /// attribute: not DICOM, another SOP class, no registration item for another frame, a matrix that is not 16 numbers,
  /// not RIGID or not a rotation plus translation.
  static Result<DicomRegistration> read(const std::filesystem::path& path);
};

}  // namespace fct
