#pragma once
// SyntheticCtDicom: one small uncompressed CT slice as a DCMTK dataset, for the Core tests and the fuzz seeds.

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <fmt/core.h>

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

namespace fct::test {

/// The tags of one synthetic CT slice; stored(i, j) gives the raw stored value of column i, row j.
struct SyntheticSlice {
  std::string seriesUid = "1.2.826.0.1.3680043.9.9999.1";
  int cols = 5, rows = 4;
  Eigen::Vector3d ipp_lps_mm = Eigen::Vector3d::Zero();
  std::array<double, 6> iop = {1, 0, 0, 0, 1, 0};
  bool withPixelSpacing = true, withPixelData = true;
  double rowSpacing_mm = 0.5, columnSpacing_mm = 0.8;  // PixelSpacing = row spacing \ column spacing
  double sliceThickness_mm = 0.0;                      // 0: no SliceThickness tag
  int pixelRepresentation = 1;
  double slope = 1.0, intercept = 0.0;
  std::function<int(int, int)> stored = [](int i, int j) { return 10 * j + i; };
  E_TransferSyntax transferSyntax = EXS_LittleEndianExplicit;

  /// The slice as an Explicit VR Little Endian dataset (transferSyntax is for the caller's saveFile).
  DcmFileFormat build() const {
    DcmFileFormat file;
    DcmDataset* ds = file.getDataset();
    char uid[100];
    ds->putAndInsertString(DCM_SOPClassUID, UID_CTImageStorage);
    ds->putAndInsertString(DCM_SOPInstanceUID, dcmGenerateUniqueIdentifier(uid, SITE_INSTANCE_UID_ROOT));
    ds->putAndInsertString(DCM_Modality, "CT");
    ds->putAndInsertString(DCM_SeriesInstanceUID, seriesUid.c_str());
    ds->putAndInsertString(DCM_SeriesDescription, "synthetic");
    ds->putAndInsertString(DCM_ImagePositionPatient,
                           fmt::format("{}\\{}\\{}", ipp_lps_mm.x(), ipp_lps_mm.y(), ipp_lps_mm.z()).c_str());
    ds->putAndInsertString(DCM_ImageOrientationPatient,
                           fmt::format("{}\\{}\\{}\\{}\\{}\\{}", iop[0], iop[1], iop[2], iop[3], iop[4], iop[5]).c_str());
    if (withPixelSpacing) {
      ds->putAndInsertString(DCM_PixelSpacing, fmt::format("{}\\{}", rowSpacing_mm, columnSpacing_mm).c_str());
    }
    if (sliceThickness_mm > 0) ds->putAndInsertString(DCM_SliceThickness, fmt::format("{}", sliceThickness_mm).c_str());
    ds->putAndInsertUint16(DCM_Rows, static_cast<Uint16>(rows));
    ds->putAndInsertUint16(DCM_Columns, static_cast<Uint16>(cols));
    ds->putAndInsertUint16(DCM_SamplesPerPixel, 1);
    ds->putAndInsertString(DCM_PhotometricInterpretation, "MONOCHROME2");
    ds->putAndInsertUint16(DCM_BitsAllocated, 16);
    ds->putAndInsertUint16(DCM_BitsStored, 16);
    ds->putAndInsertUint16(DCM_HighBit, 15);
    ds->putAndInsertUint16(DCM_PixelRepresentation, static_cast<Uint16>(pixelRepresentation));
    ds->putAndInsertString(DCM_RescaleSlope, fmt::format("{}", slope).c_str());
    ds->putAndInsertString(DCM_RescaleIntercept, fmt::format("{}", intercept).c_str());
    if (withPixelData) {
      std::vector<Uint16> pixels;
      for (int j = 0; j < rows; ++j) {
        for (int i = 0; i < cols; ++i) pixels.push_back(static_cast<Uint16>(stored(i, j)));
      }
      ds->putAndInsertUint16Array(DCM_PixelData, pixels.data(), pixels.size());
    }
    return file;
  }
};

}  // namespace fct::test
