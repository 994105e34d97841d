#pragma once
// SyntheticXrayDicom: small uncompressed X-ray DICOM files made with DCMTK for the Core tests, with the C-arm
// geometry tags of classic XA files, Enhanced XA functional groups or a rotational run.

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcuid.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace fct::test {

/// A small uncompressed X-ray DICOM dataset; tests add or change tags before saving.
struct SyntheticXray {
  std::string modality = "XA";
  std::string photometric = "MONOCHROME2";
  int cols = 5;
  int rows = 4;
  int frames = 1;
  int bitsAllocated = 16;
  int bitsStored = 16;
  std::vector<Uint16> samples;  ///< frames*rows*cols raw values (8-bit when bitsAllocated == 8); empty = zeros

  DcmFileFormat build() const {
    DcmFileFormat file;
    DcmDataset* ds = file.getDataset();
    char uid[100];
    ds->putAndInsertString(DCM_SOPClassUID, UID_XRayAngiographicImageStorage);
    ds->putAndInsertString(DCM_SOPInstanceUID, dcmGenerateUniqueIdentifier(uid, SITE_INSTANCE_UID_ROOT));
    ds->putAndInsertString(DCM_Modality, modality.c_str());
    ds->putAndInsertUint16(DCM_SamplesPerPixel, 1);
    ds->putAndInsertString(DCM_PhotometricInterpretation, photometric.c_str());
    ds->putAndInsertUint16(DCM_Rows, static_cast<Uint16>(rows));
    ds->putAndInsertUint16(DCM_Columns, static_cast<Uint16>(cols));
    if (frames > 1) ds->putAndInsertString(DCM_NumberOfFrames, std::to_string(frames).c_str());
    ds->putAndInsertUint16(DCM_BitsAllocated, static_cast<Uint16>(bitsAllocated));
    ds->putAndInsertUint16(DCM_BitsStored, static_cast<Uint16>(bitsStored));
    ds->putAndInsertUint16(DCM_HighBit, static_cast<Uint16>(bitsStored - 1));
    ds->putAndInsertUint16(DCM_PixelRepresentation, 0);
    const std::vector<Uint16> values =
        samples.empty() ? std::vector<Uint16>(static_cast<std::size_t>(frames) * rows * cols, 0) : samples;
    if (bitsAllocated == 8) {
      std::vector<Uint8> bytes(values.begin(), values.end());
      if (bytes.size() % 2) bytes.push_back(0);
      ds->putAndInsertUint8Array(DCM_PixelData, bytes.data(), bytes.size());
    } else {
      ds->putAndInsertUint16Array(DCM_PixelData, values.data(), values.size());
    }
    return file;
  }
};

/// Sets the classic C-arm tags: SID, SOD, ImagerPixelSpacing (given as du, dv; stored row spacing first) and angles.
inline void putCarmTags(DcmItem& item, double sid_mm, double sod_mm, double du_mm, double dv_mm, double primary_deg,
                        double secondary_deg) {
  item.putAndInsertString(DCM_DistanceSourceToDetector, std::to_string(sid_mm).c_str());
  item.putAndInsertString(DCM_DistanceSourceToPatient, std::to_string(sod_mm).c_str());
  item.putAndInsertString(DCM_ImagerPixelSpacing, (std::to_string(dv_mm) + "\\" + std::to_string(du_mm)).c_str());
  item.putAndInsertString(DCM_PositionerPrimaryAngle, std::to_string(primary_deg).c_str());
  item.putAndInsertString(DCM_PositionerSecondaryAngle, std::to_string(secondary_deg).c_str());
}

/// Saves a dataset as Explicit VR Little Endian; returns the path.
inline std::filesystem::path save(DcmFileFormat& file, const std::filesystem::path& path) {
  EXPECT_TRUE(file.saveFile(path.c_str(), EXS_LittleEndianExplicit).good()) << path;
  return path;
}

}  // namespace fct::test
