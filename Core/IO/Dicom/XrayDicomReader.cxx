#include "IO/Dicom/XrayDicomReader.h"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcpixel.h>
#include <dcmtk/dcmdata/dcsequen.h>
#include <dcmtk/dcmdata/dcxfer.h>
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "IO/Dicom/DicomCodecs.h"
#include "IO/Dicom/DicomElementLengthCheck.h"
#include "IO/Dicom/DicomIdentityReader.h"
#include "IO/Dicom/DicomValues.h"

namespace fct {

namespace {

std::string stringTag(DcmItem& item, const DcmTagKey& tag) { return DicomValues::text(item, tag, 0); }

std::optional<double> numberTag(DcmItem& item, const DcmTagKey& tag, unsigned long pos = 0) {
  return DicomValues::number(item, tag, pos);
}

std::optional<int> intTag(DcmItem& item, const DcmTagKey& tag) {
  const auto value = numberTag(item, tag);
  if (!value) return std::nullopt;
  return static_cast<int>(std::lround(*value));
}

/// A loaded file with its validated header and the pixel layout facts read() needs.
struct LoadedFile {
  DcmFileFormat file;
  XrayDicomHeader header;
  int highBit = 0;
  bool signedPixels = false;
};

Status loadAndValidate(const std::filesystem::path& path, int frame, LoadedFile& loaded,
                       std::vector<std::string>& warnings) {
  DicomCodecs::ensureRegistered();
  const std::string name = path.filename().string();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return fail(fmt::format("X-ray file '{}' does not exist", path.string()));
  if (Status lengths = DicomElementLengthCheck::check(path); !lengths) return lengths;
  const OFCondition status = loaded.file.loadFile(path.c_str(), EXS_Unknown, EGL_noChange, DCM_MaxReadLength, ERM_autoDetect);
  if (status.bad()) {
    return fail(fmt::format("'{}' is not a readable DICOM file ({}); it may be truncated or not DICOM at all", name,
                            status.text()));
  }
  DcmDataset& ds = *loaded.file.getDataset();
  XrayDicomHeader& h = loaded.header;
  h.modality = stringTag(ds, DCM_Modality);
  h.sopClassUid = stringTag(ds, DCM_SOPClassUID);
  if (h.modality.empty() && h.sopClassUid.empty()) {
    return fail(fmt::format("'{}' has neither Modality (0008,0060) nor SOPClassUID; it is not a DICOM image file", name));
  }
  static const std::array<std::string, 4> kXrayModalities{"XA", "RF", "DX", "CR"};
  if (std::find(kXrayModalities.begin(), kXrayModalities.end(), h.modality) == kXrayModalities.end()) {
    if (h.modality.empty()) return fail(fmt::format("'{}' has no Modality (0008,0060); expected XA, RF, DX or CR", name));
    return fail(fmt::format("'{}' has modality {}, not an X-ray projection image (XA, RF, DX or CR){}", name, h.modality,
                            h.modality == "CT" ? "; a CT slice belongs to a CT series import" : ""));
  }
  const int samples = intTag(ds, DCM_SamplesPerPixel).value_or(1);
  h.photometric = stringTag(ds, DCM_PhotometricInterpretation);
  if (samples != 1 || (h.photometric != "MONOCHROME1" && h.photometric != "MONOCHROME2")) {
    return fail(fmt::format("'{}' is {} with {} samples per pixel; FluoroCT reads grey-scale X-rays only "
                            "(MONOCHROME1 or MONOCHROME2); export the image as grey scale",
                            name, h.photometric.empty() ? "of unknown photometric interpretation" : h.photometric,
                            samples));
  }
  h.cols = intTag(ds, DCM_Columns).value_or(0);
  h.rows = intTag(ds, DCM_Rows).value_or(0);
  if (h.cols <= 0 || h.rows <= 0) {
    return fail(fmt::format("'{}' has an image size of {} x {} pixels (Columns x Rows); it holds no image", name, h.cols,
                            h.rows));
  }
  h.frames = intTag(ds, DCM_NumberOfFrames).value_or(1);
  if (h.frames < 1) return fail(fmt::format("'{}' has NumberOfFrames = {}; expected at least 1", name, h.frames));
  h.bitsAllocated = intTag(ds, DCM_BitsAllocated).value_or(0);
  h.bitsStored = intTag(ds, DCM_BitsStored).value_or(h.bitsAllocated);
  loaded.highBit = intTag(ds, DCM_HighBit).value_or(h.bitsStored - 1);
  loaded.signedPixels = intTag(ds, DCM_PixelRepresentation).value_or(0) == 1;
  if (h.bitsAllocated != 8 && h.bitsAllocated != 16) {
    return fail(fmt::format("'{}' has {} bits allocated per pixel; FluoroCT reads 8- and 16-bit X-rays", name,
                            h.bitsAllocated));
  }
  if (h.bitsStored < 1 || h.bitsStored > h.bitsAllocated || loaded.highBit >= h.bitsAllocated ||
      loaded.highBit + 1 < h.bitsStored) {
    return fail(fmt::format("'{}' has inconsistent bit layout: BitsAllocated {}, BitsStored {}, HighBit {}", name,
                            h.bitsAllocated, h.bitsStored, loaded.highBit));
  }
  const E_TransferSyntax xfer = ds.getOriginalXfer();
  h.transferSyntax = DcmXfer(xfer).getXferName();

  h.identity = DicomIdentityReader::read(ds);
  auto geometry = XrayGeometryReader::readTags(ds, frame, h.frames);
  if (!geometry) return fail(fmt::format("'{}': {}", name, geometry.error()));
  for (const auto& w : geometry.warnings()) warnings.push_back(fmt::format("'{}': {}", name, w));
  h.geometry = geometry.value();
  const XrayGeometryTags& g = h.geometry;
  if (!g.sourceToDetector_mm) h.missingGeometry.emplace_back(XrayGeometryReader::kSourceToDetectorTag);
  if (!g.sourceToPatient_mm) h.missingGeometry.emplace_back(XrayGeometryReader::kSourceToPatientTag);
  if (!g.pixelSpacing_mm) h.missingGeometry.emplace_back(XrayGeometryReader::kPixelSpacingTag);
  return Ok{};
}

/// Maps every stored value lo..hi to its MONOCHROME2-sense modality value (index = stored - lo).
Result<std::vector<float>> modalityTable(DcmItem& ds, const LoadedFile& loaded, const std::string& name) {
  const int bits = loaded.header.bitsStored;
  const long lo = loaded.signedPixels ? -(1L << (bits - 1)) : 0L;
  const long hi = loaded.signedPixels ? (1L << (bits - 1)) - 1 : (1L << bits) - 1;
  std::vector<float> table(static_cast<std::size_t>(hi - lo + 1));

  DcmItem* lutItem = nullptr;
  if (ds.findAndGetSequenceItem(DCM_ModalityLUTSequence, lutItem, 0).good() && lutItem) {
    const auto entries = intTag(*lutItem, DCM_LUTDescriptor);
    const auto firstMapped = numberTag(*lutItem, DCM_LUTDescriptor, 1);
    const Uint16* data = nullptr;
    unsigned long count = 0;
    if (!entries || !firstMapped || lutItem->findAndGetUint16Array(DCM_LUTData, data, &count).bad() || count == 0) {
      return fail(fmt::format("'{}' has an incomplete Modality LUT Sequence (0028,3000): LUTDescriptor or LUTData "
                              "missing",
                              name));
    }
    const long n = *entries == 0 ? 65536L : static_cast<long>(*entries);
    if (static_cast<long>(count) < n) {
      return fail(fmt::format("'{}': Modality LUT has {} entries in LUTDescriptor but only {} 16-bit values in LUTData; "
                              "8-bit packed LUTs are not supported",
                              name, n, count));
    }
    const long first = static_cast<long>(*firstMapped);
    for (long s = lo; s <= hi; ++s) {
      const long index = std::clamp(s - first, 0L, n - 1);
      table[static_cast<std::size_t>(s - lo)] = static_cast<float>(data[index]);
    }
  } else {
    const double slope = numberTag(ds, DCM_RescaleSlope).value_or(1.0);
    const double intercept = numberTag(ds, DCM_RescaleIntercept).value_or(0.0);
    if (slope == 0.0) return fail(fmt::format("'{}' has RescaleSlope (0028,1053) = 0; the pixel values are meaningless", name));
    for (long s = lo; s <= hi; ++s) {
      table[static_cast<std::size_t>(s - lo)] = static_cast<float>(slope * static_cast<double>(s) + intercept);
    }
  }
  if (loaded.header.photometric == "MONOCHROME1") {
    // Invert within the range of possible values: (max possible - value) for unsigned data without rescale.
    const auto [minIt, maxIt] = std::minmax_element(table.begin(), table.end());
    const float sum = *minIt + *maxIt;
    for (float& v : table) v = sum - v;
  }
  return table;
}

}  // namespace

Result<XrayDicomHeader> XrayDicomReader::readHeader(const std::filesystem::path& path, int frame) {
  LoadedFile loaded;
  std::vector<std::string> warnings;
  if (Status status = loadAndValidate(path, frame, loaded, warnings); !status) return fail(status.error());
  Result<XrayDicomHeader> result(std::move(loaded.header));
  for (auto& w : warnings) result.addWarning(std::move(w));
  return result;
}

Result<XrayImage> XrayDicomReader::read(const std::filesystem::path& path, int frameIndex) {
  LoadedFile loaded;
  std::vector<std::string> warnings;
  if (Status status = loadAndValidate(path, frameIndex, loaded, warnings); !status) return fail(status.error());
  const XrayDicomHeader& h = loaded.header;
  const std::string name = path.filename().string();
  DcmDataset& ds = *loaded.file.getDataset();
  const E_TransferSyntax xfer = ds.getOriginalXfer();
  const bool encapsulated = DcmXfer(xfer).isEncapsulated();
  DcmElement* element = nullptr;
  if (ds.findAndGetElement(DCM_PixelData, element).bad() || !element || (!encapsulated && element->getLength() == 0)) {
    return fail(fmt::format("'{}' has no pixel data (7FE0,0010); it may be a header-only or structured-report object",
                            name));
  }
  auto* pixelData = dynamic_cast<DcmPixelData*>(element);
  if (!pixelData) return fail(fmt::format("'{}': pixel data (7FE0,0010) has an unexpected encoding", name));

  const std::size_t bytesPerSample = static_cast<std::size_t>(h.bitsAllocated / 8);
  const std::size_t frameBytes = static_cast<std::size_t>(h.cols) * h.rows * bytesPerSample;
  if (!encapsulated && element->getLength() < frameBytes * static_cast<std::size_t>(h.frames)) {
    return fail(fmt::format("'{}' is truncated: pixel data holds {} bytes but {} frame(s) of {} x {} x {} bits need {}",
                            name, element->getLength(), h.frames, h.cols, h.rows, h.bitsAllocated,
                            frameBytes * static_cast<std::size_t>(h.frames)));
  }
  std::vector<std::uint8_t> buffer(frameBytes + (frameBytes & 1U));
  Uint32 startFragment = 0;
  OFString colorModel;
  const OFCondition decoded = pixelData->getUncompressedFrame(&ds, static_cast<Uint32>(frameIndex), startFragment,
                                                              buffer.data(), static_cast<Uint32>(buffer.size()),
                                                              colorModel);
  if (decoded.bad()) {
    return fail(fmt::format("cannot decode frame {} of '{}' ({}): {}; the file may be truncated or use an unsupported "
                            "compression",
                            frameIndex, name, h.transferSyntax, decoded.text()));
  }

  auto table = modalityTable(ds, loaded, name);
  if (!table) return fail(table.error());
  const std::vector<float>& lut = table.value();

  XrayImage image;
  image.cols = h.cols;
  image.rows = h.rows;
  image.bitsStored = h.bitsStored;
  image.photometric = h.photometric;
  image.modality = h.modality;
  image.frameIndex = frameIndex;
  image.frameCount = h.frames;
  image.sourcePath = path.string();
  image.pixels.resize(static_cast<std::size_t>(h.cols) * h.rows);

  const int shift = loaded.highBit + 1 - h.bitsStored;
  const std::uint32_t mask = (1U << h.bitsStored) - 1U;  // bitsStored <= 16 (validated)
  const std::uint32_t signBit = 1U << (h.bitsStored - 1);
  const long lo = loaded.signedPixels ? -(1L << (h.bitsStored - 1)) : 0L;
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    std::uint32_t raw = 0;
    if (bytesPerSample == 1) {
      raw = buffer[i];
    } else {
      std::uint16_t word = 0;
      std::memcpy(&word, buffer.data() + 2 * i, 2);  // DCMTK returns the frame in local byte order
      raw = word;
    }
    const std::uint32_t bitsValue = (raw >> shift) & mask;
    const long stored = (loaded.signedPixels && (bitsValue & signBit)) ? static_cast<long>(bitsValue) - (1L << h.bitsStored)
                                                                        : static_cast<long>(bitsValue);
    image.pixels[i] = lut[static_cast<std::size_t>(stored - lo)];
  }

  if (h.missingGeometry.empty()) {
    auto camera = XrayGeometryReader::frameCamera(h.geometry, h.cols, h.rows, {});
    for (const auto& w : camera.warnings()) warnings.push_back(fmt::format("'{}': {}", name, w));
    if (!camera) {
      warnings.push_back(fmt::format("'{}': no camera from the DICOM tags: {}", name, camera.error()));
    } else if (camera.value().mirrorColumns) {
      warnings.push_back(fmt::format("'{}': PatientOrientation (0020,0020) {} says the image is stored mirrored (as "
                                     "displayed) against the view from the source, so no camera is attached to the "
                                     "stored pixels; a view with \"mirror_columns\": true flips it ('fluoroct views "
                                     "--from-dicom' writes one)",
                                     name, h.geometry.patientOrientation));
    } else {
      image.camera = camera.value().camera;
    }
  } else {
    std::string missing;
    for (const auto& m : h.missingGeometry) missing += (missing.empty() ? "" : ", ") + m;
    warnings.push_back(fmt::format("'{}' has no complete geometry (missing {}); supply the camera in a view file", name,
                                   missing));
  }
  Result<XrayImage> result(std::move(image));
  for (auto& w : warnings) result.addWarning(std::move(w));
  return result;
}

}  // namespace fct
