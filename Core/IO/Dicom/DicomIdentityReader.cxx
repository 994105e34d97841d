#include "IO/Dicom/DicomIdentityReader.h"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcitem.h>

#include "IO/Dicom/DicomValues.h"

namespace fct {

DicomIdentity DicomIdentityReader::read(DcmItem& dataset) {
  auto get = [&dataset](const DcmTagKey& key) { return DicomValues::text(dataset, key); };
  DicomIdentity identity;
  identity.patientName = get(DCM_PatientName);
  identity.patientId = get(DCM_PatientID);
  identity.patientBirthDate = get(DCM_PatientBirthDate);
  identity.patientSex = get(DCM_PatientSex);
  identity.studyInstanceUid = get(DCM_StudyInstanceUID);
  identity.studyDate = get(DCM_StudyDate);
  identity.studyTime = get(DCM_StudyTime);
  identity.studyId = get(DCM_StudyID);
  identity.accessionNumber = get(DCM_AccessionNumber);
  identity.referringPhysicianName = get(DCM_ReferringPhysicianName);
  identity.seriesInstanceUid = get(DCM_SeriesInstanceUID);
  identity.modality = get(DCM_Modality);
  identity.frameOfReferenceUid = get(DCM_FrameOfReferenceUID);
  identity.specificCharacterSet = get(DCM_SpecificCharacterSet);
  DicomInstance self{get(DCM_SOPClassUID), get(DCM_SOPInstanceUID)};
  if (!self.sopInstanceUid.empty()) identity.instances.push_back(std::move(self));
  return identity;
}

}  // namespace fct
