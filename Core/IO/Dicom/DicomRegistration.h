#pragma once
// DicomRegistration: the content of a DICOM Spatial Registration object (modality REG) as FluoroCT writes and reads
// it: the bone pose T_world_from_ct registering the CT's Frame of Reference to the C-arm world's.

#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "Image/DicomIdentity.h"

namespace fct {

/// A rigid registration of a CT to the C-arm world, with what it refers to.
struct DicomRegistration {
  /// Maps CT patient coordinates (LPS mm, the CT's Frame of Reference) to the world (the registration's frame).
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  /// Patient, study, series, Frame of Reference UID and slices of the CT; the REG object takes patient and study
  /// from it. A CT not read from DICOM carries a generated Frame of Reference UID and no instances.
  DicomIdentity ct;
  /// The world's Frame of Reference UID: the registration's own frame (the X-rays' when they have one).
  std::string worldFrameOfReferenceUid;
  /// The registered X-ray instances (their study, series and SOP instance); empty when the views are not DICOM.
  std::vector<DicomIdentity> xrays;
  std::string contentDescription;  ///< free text, e.g. the final similarity
  std::string sopInstanceUid;      ///< of the REG object itself (the writer generates one when empty)
  std::string seriesInstanceUid;   ///< of the REG object's series (the writer generates one when empty)
};

}  // namespace fct
