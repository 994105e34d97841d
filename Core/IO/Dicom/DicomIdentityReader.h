#pragma once
// DicomIdentityReader: the patient, study, series, frame of reference and SOP identity of one DICOM dataset
// (DCMTK stays inside IO/Dicom; this header is for the folder's readers).

#include "Image/DicomIdentity.h"

class DcmItem;

namespace fct {

/// Reads the identifying attributes every DICOM reader of this folder keeps.
class DicomIdentityReader {
 public:
  /// Patient (0010,xxxx), study (0020,000D; 0008,0020/0030/0050/0090; 0020,0010), series (0020,000E), modality,
  /// Frame of Reference UID (0020,0052), Specific Character Set and the dataset's own SOP class/instance as `instances[0]` (left out when the
  /// dataset has no SOP Instance UID). Absent attributes come back as empty strings; never fails.
  static DicomIdentity read(DcmItem& dataset);
};

}  // namespace fct
