#pragma once
// DicomIdentity: who and what a set of DICOM images belongs to (patient, study, series, frame of reference and the
// instances themselves), kept from import so that objects written later (a DICOM registration) can refer back.

#include <string>
#include <vector>

namespace fct {

/// One DICOM instance, as a reference needs it.
struct DicomInstance {
  std::string sopClassUid;
  std::string sopInstanceUid;
};

/// Patient, study, series and frame of reference of images read from DICOM; empty strings = absent in the files.
struct DicomIdentity {
  std::string patientName, patientId, patientBirthDate, patientSex;
  std::string studyInstanceUid, studyDate, studyTime, studyId, accessionNumber, referringPhysicianName;
  std::string seriesInstanceUid, modality, frameOfReferenceUid;
  std::string specificCharacterSet;      ///< (0008,0005), e.g. "ISO_IR 100"; empty = default repertoire
  std::vector<DicomInstance> instances;  ///< the images of the series that were read, in slice or file order
};

}  // namespace fct
