#include "IO/Dicom/DicomRegistrationWriter.h"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcitem.h>
#include <dcmtk/dcmdata/dcostrmb.h>
#include <dcmtk/dcmdata/dcsequen.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <fmt/core.h>

#include <ctime>
#include <tuple>
#include <map>
#include <set>

#include "Base/TextFile.h"
#include "IO/Dicom/XrayDicomReader.h"

namespace fct {

namespace {

std::string newUid(const char* root) {
  char uid[100];
  return dcmGenerateUniqueIdentifier(uid, root);
}

/// The current local date (YYYYMMDD) and time (HHMMSS) in DICOM DA/TM form.
std::pair<std::string, std::string> now() {
  const std::time_t t = std::time(nullptr);
  std::tm local{};
  localtime_r(&t, &local);
  char date[16], time[16];
  std::strftime(date, sizeof date, "%Y%m%d", &local);
  std::strftime(time, sizeof time, "%H%M%S", &local);
  return {date, time};
}

/// A rigid transform's problem in words, or empty when the rotation part is orthonormal with det +1.
std::string rigidityProblem(const Eigen::Matrix4d& M) {
  if (!M.allFinite()) return "it holds non-finite numbers";
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0.0) {
    return "its 3x3 part is not a rotation";
  }
  if ((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-12) return "its last row is not 0 0 0 1";
  return {};
}

/// The 16 matrix values row by row as a DS value (each at most 16 characters).
std::string matrixText(const Eigen::Matrix4d& M) {
  std::string text;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      const double v = std::abs(M(r, c)) < 1e-15 ? 0.0 : M(r, c);
      text += fmt::format("{}{:.10g}", text.empty() ? "" : "\\", v);
    }
  }
  return text;
}

void putReferencedImages(DcmItem& item, const DcmTagKey& sequence, const std::vector<DicomInstance>& instances) {
  for (std::size_t i = 0; i < instances.size(); ++i) {
    DcmItem* ref = nullptr;
    if (item.findOrCreateSequenceItem(sequence, ref, static_cast<long>(i)).bad() || !ref) continue;
    ref->putAndInsertString(DCM_ReferencedSOPClassUID, instances[i].sopClassUid.c_str());
    ref->putAndInsertString(DCM_ReferencedSOPInstanceUID, instances[i].sopInstanceUid.c_str());
  }
}

/// One Registration Sequence item: a Frame of Reference, its images and the matrix into the registered frame.
void putRegistrationItem(DcmItem& item, const std::string& frameOfReferenceUid, const std::vector<DicomInstance>& images,
                         const Eigen::Matrix4d& M_registered_from_item, const char* comment) {
  item.putAndInsertString(DCM_FrameOfReferenceUID, frameOfReferenceUid.c_str());
  if (!images.empty()) putReferencedImages(item, DCM_ReferencedImageSequence, images);
  DcmItem* matrixRegistration = nullptr;
  item.findOrCreateSequenceItem(DCM_MatrixRegistrationSequence, matrixRegistration, 0);
  matrixRegistration->putAndInsertString(DCM_FrameOfReferenceTransformationComment, comment);
  matrixRegistration->insertEmptyElement(DCM_RegistrationTypeCodeSequence);
  DcmItem* matrix = nullptr;
  matrixRegistration->findOrCreateSequenceItem(DCM_MatrixSequence, matrix, 0);
  matrix->putAndInsertString(DCM_FrameOfReferenceTransformationMatrix, matrixText(M_registered_from_item).c_str());
  matrix->putAndInsertString(DCM_FrameOfReferenceTransformationMatrixType, "RIGID");
}

/// Common Instance Reference module: series of the REG's study in Referenced Series, the others per study.
void putInstanceReferences(DcmDataset& ds, const std::string& studyUid, const std::vector<DicomIdentity>& sources) {
  // study -> series -> instances, each level sorted by UID
  std::map<std::string, std::map<std::string, std::vector<DicomInstance>>> byStudy;
  for (const DicomIdentity& source : sources) {
    if (source.instances.empty() || source.seriesInstanceUid.empty()) continue;
    auto& instances = byStudy[source.studyInstanceUid][source.seriesInstanceUid];
    instances.insert(instances.end(), source.instances.begin(), source.instances.end());
  }
  auto putSeries = [](DcmItem& parent, const std::map<std::string, std::vector<DicomInstance>>& series) {
    long n = 0;
    for (const auto& [seriesUid, instances] : series) {
      DcmItem* item = nullptr;
      parent.findOrCreateSequenceItem(DCM_ReferencedSeriesSequence, item, n++);
      item->putAndInsertString(DCM_SeriesInstanceUID, seriesUid.c_str());
      putReferencedImages(*item, DCM_ReferencedInstanceSequence, instances);
    }
  };
  long otherStudies = 0;
  for (const auto& [study, series] : byStudy) {
    if (study == studyUid) {
      putSeries(ds, series);
    } else if (!study.empty()) {
      DcmItem* item = nullptr;
      ds.findOrCreateSequenceItem(DCM_StudiesContainingOtherReferencedInstancesSequence, item, otherStudies++);
      item->putAndInsertString(DCM_StudyInstanceUID, study.c_str());
      putSeries(*item, series);
    }
  }
}

}  // namespace

Result<DicomRegistration> DicomRegistrationWriter::describe(const Volume& ct, const Eigen::Isometry3d& T_world_from_ct,
                                                            const std::vector<std::filesystem::path>& xrayDicomFiles) {
  if (std::string problem = rigidityProblem(T_world_from_ct.matrix()); !problem.empty()) {
    return fail(fmt::format("the bone pose T_world_from_ct is not rigid: {}", problem));
  }
  DicomRegistration registration;
  registration.T_world_from_ct = T_world_from_ct;
  std::vector<std::string> warnings;
  if (ct.dicom && !ct.dicom->frameOfReferenceUid.empty()) {
    registration.ct = *ct.dicom;
  } else {
    if (ct.dicom) registration.ct = *ct.dicom;
    registration.ct.frameOfReferenceUid = newUid(SITE_UID_ROOT);
    if (registration.ct.studyInstanceUid.empty()) {  // a study made here dates from now
      registration.ct.studyInstanceUid = newUid(SITE_STUDY_UID_ROOT);
      std::tie(registration.ct.studyDate, registration.ct.studyTime) = now();
    }
    warnings.push_back(fmt::format("the CT was not read from a DICOM series with a Frame of Reference UID; the "
                                   "registration names its frame by a generated Frame of Reference UID {}, so a "
                                   "viewer cannot match it to the CT by itself",
                                   registration.ct.frameOfReferenceUid));
  }
  std::set<std::string> xrayFrames;
  for (const auto& file : xrayDicomFiles) {
    auto header = XrayDicomReader::readHeader(file);
    if (!header) return fail(fmt::format("cannot reference X-ray '{}': {}", file.string(), header.error()));
    registration.xrays.push_back(header.value().identity);
    if (!header.value().identity.frameOfReferenceUid.empty()) {
      xrayFrames.insert(header.value().identity.frameOfReferenceUid);
    }
  }
  if (xrayFrames.size() == 1 && *xrayFrames.begin() != registration.ct.frameOfReferenceUid) {
    registration.worldFrameOfReferenceUid = *xrayFrames.begin();
  } else {
    registration.worldFrameOfReferenceUid = newUid(SITE_UID_ROOT);
    if (!xrayFrames.empty()) {
      warnings.push_back(fmt::format("the X-rays carry {} Frame of Reference UIDs{}; the C-arm world gets a new one, {}",
                                     xrayFrames.size(), xrayFrames.size() == 1 ? " (the CT's own)" : "",
                                     registration.worldFrameOfReferenceUid));
    }
  }
  Result<DicomRegistration> result(std::move(registration));
  for (auto& w : warnings) result.addWarning(std::move(w));
  return result;
}

Status DicomRegistrationWriter::write(const DicomRegistration& registration, const std::filesystem::path& path) {
  const std::string target = path.string();
  if (registration.ct.frameOfReferenceUid.empty() || registration.worldFrameOfReferenceUid.empty()) {
    return fail(fmt::format("cannot write '{}': the CT's and the world's Frame of Reference UIDs are both needed",
                            target));
  }
  if (registration.ct.frameOfReferenceUid == registration.worldFrameOfReferenceUid) {
    return fail(fmt::format("cannot write '{}': the CT and the world share the Frame of Reference UID {}", target,
                            registration.ct.frameOfReferenceUid));
  }
  const Eigen::Matrix4d M = registration.T_world_from_ct.matrix();
  if (std::string problem = rigidityProblem(M); !problem.empty()) {
    return fail(fmt::format("cannot write '{}': T_world_from_ct is not rigid: {}", target, problem));
  }
  const DicomIdentity& ct = registration.ct;
  const auto [date, time] = now();
  DcmFileFormat file;
  DcmDataset& ds = *file.getDataset();
  auto put = [&ds](const DcmTagKey& tag, const std::string& value) { ds.putAndInsertString(tag, value.c_str()); };

  // SOP Common
  put(DCM_SpecificCharacterSet, ct.specificCharacterSet.empty() ? "ISO_IR 192" : ct.specificCharacterSet);
  put(DCM_SOPClassUID, UID_SpatialRegistrationStorage);
  put(DCM_SOPInstanceUID,
      registration.sopInstanceUid.empty() ? newUid(SITE_INSTANCE_UID_ROOT) : registration.sopInstanceUid);
  put(DCM_InstanceCreationDate, date);
  put(DCM_InstanceCreationTime, time);
  // Patient and General Study, from the CT
  put(DCM_PatientName, ct.patientName);
  put(DCM_PatientID, ct.patientId);
  put(DCM_PatientBirthDate, ct.patientBirthDate);
  put(DCM_PatientSex, ct.patientSex);
  put(DCM_StudyInstanceUID, ct.studyInstanceUid.empty() ? newUid(SITE_STUDY_UID_ROOT) : ct.studyInstanceUid);
  put(DCM_StudyDate, ct.studyDate);
  put(DCM_StudyTime, ct.studyTime);
  put(DCM_ReferringPhysicianName, ct.referringPhysicianName);
  put(DCM_StudyID, ct.studyId);
  put(DCM_AccessionNumber, ct.accessionNumber);
  // General Series and Spatial Registration Series
  put(DCM_Modality, "REG");
  put(DCM_SeriesInstanceUID,
      registration.seriesInstanceUid.empty() ? newUid(SITE_SERIES_UID_ROOT) : registration.seriesInstanceUid);
  put(DCM_SeriesNumber, "9001");
  put(DCM_Laterality, "");
  put(DCM_SeriesDescription, "FluoroCT 2D/3D registration");
  put(DCM_SeriesDate, date);
  put(DCM_SeriesTime, time);
  // Frame of Reference: the registration's own frame is the C-arm world
  put(DCM_FrameOfReferenceUID, registration.worldFrameOfReferenceUid);
  put(DCM_PositionReferenceIndicator, "");
  // General Equipment
  put(DCM_Manufacturer, "FluoroCT");
  put(DCM_ManufacturerModelName, "FluoroCT 2D/3D registration");
  put(DCM_SoftwareVersions, "FluoroCT");
  // Spatial Registration, with the Content Identification macro
  put(DCM_ContentDate, date);
  put(DCM_ContentTime, time);
  put(DCM_InstanceNumber, "1");
  put(DCM_ContentLabel, "FLUOROCT_POSE");
  put(DCM_ContentDescription, registration.contentDescription.empty()
                                  ? "Bone pose from FluoroCT intensity-based 2D/3D registration"
                                  : registration.contentDescription);
  put(DCM_ContentCreatorName, "");

  std::vector<DicomInstance> xrayInstances;
  for (const DicomIdentity& xray : registration.xrays) {
    xrayInstances.insert(xrayInstances.end(), xray.instances.begin(), xray.instances.end());
  }
  DcmItem* ctItem = nullptr;
  DcmItem* worldItem = nullptr;
  ds.findOrCreateSequenceItem(DCM_RegistrationSequence, ctItem, 0);
  ds.findOrCreateSequenceItem(DCM_RegistrationSequence, worldItem, 1);
  if (!ctItem || !worldItem) return fail(fmt::format("cannot write '{}': DCMTK could not build the sequence", target));
  putRegistrationItem(*ctItem, ct.frameOfReferenceUid, ct.instances, M,
                      "T_world_from_ct: CT patient LPS mm to C-arm world LPS mm");
  putRegistrationItem(*worldItem, registration.worldFrameOfReferenceUid, xrayInstances, Eigen::Matrix4d::Identity(),
                      "C-arm world LPS mm: identity");
  // Common Instance Reference
  std::vector<DicomIdentity> sources{ct};
  sources.insert(sources.end(), registration.xrays.begin(), registration.xrays.end());
  OFString studyUid;
  ds.findAndGetOFString(DCM_StudyInstanceUID, studyUid);
  putInstanceReferences(ds, studyUid.c_str(), sources);

  // Serialize to memory, then write atomically.
  const E_TransferSyntax xfer = EXS_LittleEndianExplicit;
  OFCondition status = file.validateMetaInfo(xfer);
  if (status.good()) {
    file.removeInvalidGroups();
    const Uint32 length = file.calcElementLength(xfer, EET_ExplicitLength);
    std::string bytes(length + 1024, '\0');
    DcmOutputBufferStream stream(bytes.data(), static_cast<offile_off_t>(bytes.size()));
    file.transferInit();
    status = file.write(stream, xfer, EET_ExplicitLength, nullptr);
    file.transferEnd();
    if (status.good()) {
      void* buffer = nullptr;
      offile_off_t written = 0;
      stream.flushBuffer(buffer, written);
      bytes.resize(static_cast<std::size_t>(written));
      return TextFile::writeAtomically(path, bytes);
    }
  }
  return fail(fmt::format("cannot write '{}': DCMTK could not encode the registration: {}", target, status.text()));
}

}  // namespace fct
