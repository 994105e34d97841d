#include "IO/Dicom/DicomRegistrationReader.h"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcitem.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <fmt/core.h>

#include "IO/Dicom/DicomElementLengthCheck.h"
#include "IO/Dicom/DicomIdentityReader.h"
#include "IO/Dicom/DicomValues.h"

namespace fct {

namespace {

/// The product of an item's Matrix Sequence (first item leftmost, PS3.3 C.20.2), checked to be RIGID.
Result<Eigen::Matrix4d> registrationMatrix(DcmItem& registrationItem, const std::string& where) {
  DcmItem* matrixRegistration = nullptr;
  if (registrationItem.findAndGetSequenceItem(DCM_MatrixRegistrationSequence, matrixRegistration, 0).bad()) {
    return fail(fmt::format("{} has no Matrix Registration Sequence (0070,0309)", where));
  }
  Eigen::Matrix4d product = Eigen::Matrix4d::Identity();
  DcmItem* matrixItem = nullptr;
  int count = 0;
  for (; matrixRegistration->findAndGetSequenceItem(DCM_MatrixSequence, matrixItem, count).good(); ++count) {
    const std::string type = DicomValues::text(*matrixItem, DCM_FrameOfReferenceTransformationMatrixType);
    if (type != "RIGID") {
      return fail(fmt::format("{}: Frame of Reference Transformation Matrix Type (0070,030C) is '{}'; FluoroCT reads "
                              "RIGID registrations only",
                              where, type));
    }
    if (DicomValues::count(*matrixItem, DCM_FrameOfReferenceTransformationMatrix) != 16) {
      return fail(fmt::format("{}: Frame of Reference Transformation Matrix (3006,00C6) must hold 16 numbers", where));
    }
    Eigen::Matrix4d M;
    for (int i = 0; i < 16; ++i) {
      const auto v = DicomValues::number(*matrixItem, DCM_FrameOfReferenceTransformationMatrix,
                                         static_cast<unsigned long>(i));
      if (!v) return fail(fmt::format("{}: matrix value {} is not a number", where, i + 1));
      M(i / 4, i % 4) = *v;  // row by row
    }
    product = product * M;
  }
  if (count == 0) return fail(fmt::format("{} has an empty Matrix Sequence (0070,030A)", where));
  const Eigen::Matrix3d R = product.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-5 || R.determinant() < 0.0 ||
      (product.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-9) {
    return fail(fmt::format("{}: the RIGID matrix is not a rotation plus translation", where));
  }
  return product;
}

std::vector<DicomInstance> referencedImages(DcmItem& item) {
  std::vector<DicomInstance> instances;
  DcmItem* ref = nullptr;
  for (long i = 0; item.findAndGetSequenceItem(DCM_ReferencedImageSequence, ref, i).good(); ++i) {
    instances.push_back({DicomValues::text(*ref, DCM_ReferencedSOPClassUID),
                         DicomValues::text(*ref, DCM_ReferencedSOPInstanceUID)});
  }
  return instances;
}

}  // namespace

Result<DicomRegistration> DicomRegistrationReader::read(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail(fmt::format("registration file '{}' does not exist", name));
  if (Status lengths = DicomElementLengthCheck::check(path); !lengths) return fail(lengths.error());
  DcmFileFormat file;
  if (const OFCondition status = file.loadFile(path.c_str()); status.bad()) {
    return fail(fmt::format("'{}' is not a readable DICOM file ({})", name, status.text()));
  }
  DcmDataset& ds = *file.getDataset();
  const std::string sopClass = DicomValues::text(ds, DCM_SOPClassUID);
  if (sopClass != UID_SpatialRegistrationStorage) {
    return fail(fmt::format("'{}' is not a Spatial Registration object: SOP Class UID is '{}', expected {} (modality "
                            "REG)",
                            name, sopClass, UID_SpatialRegistrationStorage));
  }
  DicomRegistration registration;
  registration.ct = DicomIdentityReader::read(ds);
  registration.seriesInstanceUid = registration.ct.seriesInstanceUid;  // the REG's own series, not the CT's
  registration.ct.seriesInstanceUid.clear();
  registration.ct.modality.clear();
  registration.ct.instances.clear();
  registration.worldFrameOfReferenceUid = DicomValues::text(ds, DCM_FrameOfReferenceUID);
  registration.sopInstanceUid = DicomValues::text(ds, DCM_SOPInstanceUID);
  registration.contentDescription = DicomValues::text(ds, DCM_ContentDescription);
  if (registration.worldFrameOfReferenceUid.empty()) {
    return fail(fmt::format("'{}' has no Frame of Reference UID (0020,0052): the registered frame is unknown", name));
  }
  bool found = false;
  DcmItem* item = nullptr;
  for (long i = 0; ds.findAndGetSequenceItem(DCM_RegistrationSequence, item, i).good(); ++i) {
    const std::string frame = DicomValues::text(*item, DCM_FrameOfReferenceUID);
    const std::string where = fmt::format("'{}': Registration Sequence item {}", name, i + 1);
    if (frame == registration.worldFrameOfReferenceUid) {
      registration.xrays.push_back(DicomIdentity{});
      registration.xrays.back().instances = referencedImages(*item);
      if (registration.xrays.back().instances.empty()) registration.xrays.pop_back();
      continue;
    }
    if (found) continue;
    auto matrix = registrationMatrix(*item, where);
    if (!matrix) return fail(matrix.error());
    registration.T_world_from_ct.matrix() = matrix.value();
    registration.ct.frameOfReferenceUid = frame;
    registration.ct.instances = referencedImages(*item);
    found = true;
  }
  if (!found) {
    return fail(fmt::format("'{}' has no Registration Sequence (0070,0308) item for a frame other than its own ({}); "
                            "there is nothing to register",
                            name, registration.worldFrameOfReferenceUid));
  }
  return registration;
}

}  // namespace fct
