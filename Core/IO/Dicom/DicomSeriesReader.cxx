#include "IO/Dicom/DicomSeriesReader.h"

#include <dcmtk/dcmdata/dcdeftag.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcxfer.h>
#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>

#include <optional>

#include "IO/Dicom/DicomCodecs.h"
#include "IO/Dicom/DicomElementLengthCheck.h"
#include "IO/Dicom/DicomIdentityReader.h"
#include "IO/Dicom/SliceStack.h"

namespace fct {

namespace {

namespace fs = std::filesystem;

/// The header fields of one DICOM image file that series grouping, sorting and decoding need.
struct SliceHeader {
  fs::path path;
  std::string seriesUid, seriesDescription, modality;
  bool hasPixelData = false;
  int rows = 0, cols = 0;
  std::optional<int> bitsAllocated, pixelRepresentation;
  int bitsStored = 0, highBit = 0, samplesPerPixel = 1, frames = 1;
  std::optional<Eigen::Vector3d> ipp_lps_mm;
  std::optional<std::array<double, 6>> iop;
  std::optional<Eigen::Vector2d> pixelSpacing_mm;  // as in the file: (between rows, between columns)
  double slope = 1.0, intercept = 0.0;
  DicomIdentity identity;  // patient, study, series, frame of reference and this file's SOP instance
  Eigen::Vector3d rowCosine() const { return {(*iop)[0], (*iop)[1], (*iop)[2]}; }
  Eigen::Vector3d columnCosine() const { return {(*iop)[3], (*iop)[4], (*iop)[5]}; }
};

/// What a recursive look through a folder found.
struct FolderContents {
  std::vector<SliceHeader> images;  // DICOM files with pixel data or an image size
  int filesLookedAt = 0;
  int dicomFiles = 0;
};

enum class Signature { None, Part10, RawDataset };

/// Part 10 files carry "DICM" at byte 128; a few old files are a bare dataset starting with group 0008.
Signature fileSignature(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::array<char, 132> bytes{};
  in.read(bytes.data(), bytes.size());
  const auto got = in.gcount();
  if (got == 132 && std::string_view(bytes.data() + 128, 4) == "DICM") return Signature::Part10;
  if (got >= 8 && bytes[0] == 0x08 && bytes[1] == 0x00) return Signature::RawDataset;
  return Signature::None;
}

std::string tagLabel(const DcmTagKey& key) {
  return fmt::format("{} {}", DcmTag(key).getTagName(), key.toString().c_str());
}

std::string getString(DcmDataset& ds, const DcmTagKey& key) {
  OFString value;
  if (ds.findAndGetOFStringArray(key, value).bad()) return {};
  std::string s = value.c_str();
  const auto end = s.find_last_not_of(" \0", std::string::npos, 2);
  return end == std::string::npos ? std::string() : s.substr(0, end + 1);
}

template <int N>
std::optional<Eigen::Matrix<double, N, 1>> getDoubles(DcmDataset& ds, const DcmTagKey& key) {
  Eigen::Matrix<double, N, 1> values;
  for (int i = 0; i < N; ++i) {
    Float64 v = 0.0;
    if (ds.findAndGetFloat64(key, v, i).bad() || !std::isfinite(v)) return std::nullopt;
    values[i] = v;
  }
  return values;
}

std::optional<int> getUint16(DcmDataset& ds, const DcmTagKey& key) {
  Uint16 v = 0;
  if (ds.findAndGetUint16(key, v).bad()) return std::nullopt;
  return v;
}

/// Parses the header of a DICOM file (pixel data is left on disk). Error when a Part 10 file cannot be parsed.
Result<SliceHeader> readHeader(const fs::path& path) {
  if (Status lengths = DicomElementLengthCheck::check(path); !lengths) return fail(lengths.error());
  DcmFileFormat file;
  const OFCondition status = file.loadFile(path.c_str(), EXS_Unknown, EGL_noChange, 1024);
  if (status.bad()) {
    return fail(fmt::format("cannot parse DICOM file {}: {} (truncated or corrupt file?)", path.string(),
                            status.text()));
  }
  DcmDataset& ds = *file.getDataset();
  SliceHeader h;
  h.path = path;
  h.seriesUid = getString(ds, DCM_SeriesInstanceUID);
  h.seriesDescription = getString(ds, DCM_SeriesDescription);
  h.modality = getString(ds, DCM_Modality);
  h.hasPixelData = ds.tagExists(DCM_PixelData);
  h.rows = getUint16(ds, DCM_Rows).value_or(0);
  h.cols = getUint16(ds, DCM_Columns).value_or(0);
  h.bitsAllocated = getUint16(ds, DCM_BitsAllocated);
  h.pixelRepresentation = getUint16(ds, DCM_PixelRepresentation);
  h.bitsStored = getUint16(ds, DCM_BitsStored).value_or(h.bitsAllocated.value_or(0));
  h.highBit = getUint16(ds, DCM_HighBit).value_or(h.bitsStored - 1);
  h.samplesPerPixel = getUint16(ds, DCM_SamplesPerPixel).value_or(1);
  Sint32 frames = 1;
  if (ds.findAndGetSint32(DCM_NumberOfFrames, frames).good()) h.frames = frames;
  if (auto ipp = getDoubles<3>(ds, DCM_ImagePositionPatient)) h.ipp_lps_mm = *ipp;
  if (auto iop = getDoubles<6>(ds, DCM_ImageOrientationPatient)) {
    h.iop = std::array<double, 6>{(*iop)[0], (*iop)[1], (*iop)[2], (*iop)[3], (*iop)[4], (*iop)[5]};
  }
  if (auto spacing = getDoubles<2>(ds, DCM_PixelSpacing)) h.pixelSpacing_mm = *spacing;
  if (auto slope = getDoubles<1>(ds, DCM_RescaleSlope)) h.slope = (*slope)[0];
  if (auto intercept = getDoubles<1>(ds, DCM_RescaleIntercept)) h.intercept = (*intercept)[0];
  h.identity = DicomIdentityReader::read(ds);
  return h;
}

/// Looks at every regular file under folder; keeps the headers of DICOM image files.
Result<FolderContents> scanFolder(const fs::path& folder) {
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    return fail(fmt::format("DICOM folder {} does not exist or is not a folder", folder.string()));
  }
  std::vector<fs::path> paths;
  for (fs::recursive_directory_iterator it(folder, fs::directory_options::skip_permission_denied, ec), end;
       !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file(ec)) paths.push_back(it->path());
  }
  if (ec) return fail(fmt::format("cannot list folder {}: {}", folder.string(), ec.message()));
  std::sort(paths.begin(), paths.end());

  FolderContents contents;
  contents.filesLookedAt = static_cast<int>(paths.size());
  // Headers are parsed in parallel (file reads and DCMTK parsing dominate), then taken in path order so the result
  // and the first error do not depend on the thread count.
  std::vector<Signature> signatures(paths.size(), Signature::None);
  std::vector<Result<SliceHeader>> headers(paths.size(), fail("not read"));
  tbb::parallel_for(std::size_t{0}, paths.size(), [&](std::size_t n) {
    signatures[n] = fileSignature(paths[n]);
    if (signatures[n] != Signature::None) headers[n] = readHeader(paths[n]);
  });
  for (std::size_t n = 0; n < paths.size(); ++n) {
    const Signature signature = signatures[n];
    if (signature == Signature::None) continue;
    Result<SliceHeader>& header = headers[n];
    if (!header) {
      if (signature == Signature::RawDataset) continue;  // a guess that did not parse: not DICOM after all
      return fail(header.error());
    }
    ++contents.dicomFiles;
    if (header.value().hasPixelData || header.value().rows > 0) contents.images.push_back(std::move(header).value());
  }
  if (contents.dicomFiles == 0) {
    return fail(fmt::format("no DICOM files found in {} ({} files looked at)", folder.string(),
                            contents.filesLookedAt));
  }
  if (contents.images.empty()) {
    return fail(fmt::format("no DICOM images found in {}: its {} DICOM files hold no pixel data (reports, "
                            "DICOMDIR or other non-image objects)", folder.string(), contents.dicomFiles));
  }
  return contents;
}

/// Image files grouped by SeriesInstanceUID.
std::map<std::string, std::vector<SliceHeader>> groupBySeries(FolderContents&& contents) {
  std::map<std::string, std::vector<SliceHeader>> series;
  for (SliceHeader& h : contents.images) series[h.seriesUid].push_back(std::move(h));
  return series;
}

/// One summary per series, the largest first.
std::vector<DicomSeriesSummary> summarize(const std::map<std::string, std::vector<SliceHeader>>& series) {
  std::vector<DicomSeriesSummary> summaries;
  for (const auto& [uid, headers] : series) {
    const SliceHeader& first = headers.front();
    summaries.push_back({uid, first.seriesDescription, first.modality, static_cast<int>(headers.size()), first.rows,
                         first.cols});
  }
  std::stable_sort(summaries.begin(), summaries.end(),
                   [](const auto& x, const auto& y) { return x.fileCount > y.fileCount; });
  return summaries;
}

/// "uid (140 CT files, 'description'), ..." for error messages and warnings.
std::string listSeries(const std::vector<DicomSeriesSummary>& summaries) {
  std::string list;
  for (const auto& s : summaries) {
    list += fmt::format("{}{} ({} {} files, '{}')", list.empty() ? "" : ", ", s.seriesInstanceUid, s.fileCount,
                        s.modality, s.seriesDescription);
  }
  return list;
}

/// Checks that one file carries everything a CT slice needs, in a form we decode.
Status checkSliceHeader(const SliceHeader& h) {
  const auto missing = [&](const DcmTagKey& key) {
    return fail(fmt::format("DICOM file {} lacks {}, which a CT slice needs", h.path.string(), tagLabel(key)));
  };
  if (!h.hasPixelData) return missing(DCM_PixelData);
  if (h.rows <= 0) return missing(DCM_Rows);
  if (h.cols <= 0) return missing(DCM_Columns);
  if (!h.bitsAllocated) return missing(DCM_BitsAllocated);
  if (!h.pixelRepresentation) return missing(DCM_PixelRepresentation);
  if (!h.ipp_lps_mm) return missing(DCM_ImagePositionPatient);
  if (!h.iop) return missing(DCM_ImageOrientationPatient);
  if (!h.pixelSpacing_mm) return missing(DCM_PixelSpacing);
  if (h.samplesPerPixel != 1) {
    return fail(fmt::format("DICOM file {} has {} samples per pixel; a CT slice has 1 (grey scale)", h.path.string(),
                            h.samplesPerPixel));
  }
  if (h.frames != 1) {
    return fail(fmt::format("DICOM file {} holds {} frames; multi-frame (enhanced) CT is not supported, export the "
                            "series as single-frame images", h.path.string(), h.frames));
  }
  if ((*h.bitsAllocated != 8 && *h.bitsAllocated != 16) || h.bitsStored < 1 || h.bitsStored > *h.bitsAllocated ||
      h.highBit < h.bitsStored - 1 || h.highBit >= *h.bitsAllocated) {
    return fail(fmt::format("DICOM file {} has BitsAllocated {}, BitsStored {}, HighBit {}; only 8- or 16-bit "
                            "integer pixels are supported", h.path.string(), *h.bitsAllocated, h.bitsStored,
                            h.highBit));
  }
  if ((h.pixelSpacing_mm->array() <= 0.0).any()) {
    return fail(fmt::format("DICOM file {} has PixelSpacing {}\\{}; it must be positive", h.path.string(),
                            (*h.pixelSpacing_mm)[0], (*h.pixelSpacing_mm)[1]));
  }
  if (h.slope == 0.0) {
    return fail(fmt::format("DICOM file {} has RescaleSlope 0; the HU values would all be equal", h.path.string()));
  }
  return Ok{};
}

/// Checks that a slice matches the first slice of its series in size, pixel spacing and orientation.
Status checkSameGrid(const SliceHeader& first, const SliceHeader& h) {
  if (h.rows != first.rows || h.cols != first.cols) {
    return fail(fmt::format("series {} mixes image sizes: {} is {}x{} but {} is {}x{}; select one size", h.seriesUid,
                            first.path.string(), first.cols, first.rows, h.path.string(), h.cols, h.rows));
  }
  if ((*h.pixelSpacing_mm - *first.pixelSpacing_mm).cwiseAbs().maxCoeff() > 1e-4 * first.pixelSpacing_mm->maxCoeff()) {
    return fail(fmt::format("series {} mixes pixel spacings: {} has {}\\{} mm but {} has {}\\{} mm", h.seriesUid,
                            first.path.string(), (*first.pixelSpacing_mm)[0], (*first.pixelSpacing_mm)[1],
                            h.path.string(), (*h.pixelSpacing_mm)[0], (*h.pixelSpacing_mm)[1]));
  }
  for (int i = 0; i < 6; ++i) {
    if (std::abs((*h.iop)[i] - (*first.iop)[i]) > 1e-4) {
      return fail(fmt::format("series {} mixes slice orientations: ImageOrientationPatient of {} differs from {} "
                              "(a localizer in the series?); remove the odd files", h.seriesUid, h.path.string(),
                              first.path.string()));
    }
  }
  return Ok{};
}

/// Stored pixel values to HU: extracts BitsStored bits below HighBit, sign-extends when signed, applies the rescale.
template <typename Raw>
void storedToHu(const Raw* raw, std::size_t count, const SliceHeader& h, float* hu) {
  const int shift = h.highBit + 1 - h.bitsStored;
  const std::uint32_t mask = (std::uint32_t{1} << h.bitsStored) - 1u;
  const std::uint32_t signBit = std::uint32_t{1} << (h.bitsStored - 1);
  const bool isSigned = *h.pixelRepresentation == 1;
  for (std::size_t i = 0; i < count; ++i) {
    const std::uint32_t bits = (static_cast<std::uint32_t>(raw[i]) >> shift) & mask;
    const std::int64_t value = isSigned && (bits & signBit) ? std::int64_t(bits) - (std::int64_t{1} << h.bitsStored)
                                                            : std::int64_t(bits);
    hu[i] = static_cast<float>(static_cast<double>(value) * h.slope + h.intercept);
  }
}

/// Reads and decodes one slice's pixel data into hu (rows × cols floats). Errors name the file.
Status decodeSlice(const SliceHeader& h, float* hu) {
  if (Status lengths = DicomElementLengthCheck::check(h.path); !lengths) return lengths;
  DcmFileFormat file;
  OFCondition status = file.loadFile(h.path.c_str());
  if (status.bad()) {
    return fail(fmt::format("cannot read DICOM file {}: {} (truncated or corrupt file?)", h.path.string(),
                            status.text()));
  }
  DcmDataset& ds = *file.getDataset();
  const E_TransferSyntax transferSyntax = ds.getOriginalXfer();
  status = ds.chooseRepresentation(EXS_LittleEndianExplicit, nullptr);
  if (status.bad()) {
    return fail(fmt::format("cannot decode the pixel data of {} (transfer syntax {}): {}", h.path.string(),
                            DcmXfer(transferSyntax).getXferName(), status.text()));
  }
  const std::size_t count = static_cast<std::size_t>(h.rows) * static_cast<std::size_t>(h.cols);
  unsigned long available = 0;
  if (*h.bitsAllocated == 16) {
    const Uint16* raw = nullptr;
    status = ds.findAndGetUint16Array(DCM_PixelData, raw, &available);
    if (status.good() && raw && available >= count) storedToHu(raw, count, h, hu);
  } else {
    const Uint8* raw = nullptr;
    status = ds.findAndGetUint8Array(DCM_PixelData, raw, &available);
    if (status.good() && raw && available >= count) storedToHu(raw, count, h, hu);
  }
  if (status.bad()) {
    return fail(fmt::format("cannot read the pixel data of {}: {} (truncated file?)", h.path.string(), status.text()));
  }
  if (available < count) {
    return fail(fmt::format("pixel data of {} holds {} values but {}x{} = {} are needed (truncated file?)",
                            h.path.string(), available, h.cols, h.rows, count));
  }
  return Ok{};
}

/// Checks a series' headers, sorts them by position along the slice normal and allocates their (empty) SliceStack.
Result<SliceStack> sortedSliceStack(std::vector<SliceHeader>& headers) {
  const std::string& uid = headers.front().seriesUid;
  for (const SliceHeader& h : headers) {
    if (Status ok = checkSliceHeader(h); !ok) return fail(ok.error());
    if (Status same = checkSameGrid(headers.front(), h); !same) return fail(same.error());
  }
  if (headers.size() < 2) {
    return fail(fmt::format("series {} has a single image ({}); a CT volume needs at least 2 slices", uid,
                            headers.front().path.string()));
  }
  const Eigen::Vector3d normal = headers.front().rowCosine().cross(headers.front().columnCosine());
  const auto position = [&](const SliceHeader& h) { return normal.dot(*h.ipp_lps_mm); };
  std::sort(headers.begin(), headers.end(),
            [&](const SliceHeader& x, const SliceHeader& y) { return position(x) < position(y); });
  std::vector<Eigen::Vector3d> origins;
  for (std::size_t m = 0; m < headers.size(); ++m) {
    if (m > 0 && position(headers[m]) - position(headers[m - 1]) < SliceStack::kMinGap_mm) {
      return fail(fmt::format("series {} has two slices at the same position {:.3f} mm ({} and {}): two acquisitions "
                              "in one series? Separate them before reading", uid, position(headers[m]),
                              headers[m - 1].path.string(), headers[m].path.string()));
    }
    origins.push_back(*headers[m].ipp_lps_mm);
  }
  const SliceHeader& first = headers.front();
  // PixelSpacing is (between rows, between columns) = (spacing along j, spacing along i).
  const Eigen::Vector2d pixelSpacing_mm((*first.pixelSpacing_mm)[1], (*first.pixelSpacing_mm)[0]);
  auto stack = SliceStack::create({first.cols, first.rows}, pixelSpacing_mm, first.rowCosine(), first.columnCosine(),
                                  std::move(origins));
  if (!stack) return fail(fmt::format("series {}: {}", uid, stack.error()));
  return stack;
}

/// "gantry tilt 16.5°", "non-uniform slice spacing 1.08–7.00 mm", or both joined by "and".
std::string describeIrregularity(const SliceStackLayout& layout) {
  std::string text;
  if (!layout.alongNormal) {
    text = layout.tilt_deg >= 0.05
               ? fmt::format("gantry tilt {:.1f}°", layout.tilt_deg)
               : fmt::format("slice positions shifted in-plane by up to {:.2f} mm", layout.maxInPlaneShift_mm);
  }
  if (!layout.uniformSpacing) {
    text += fmt::format("{}non-uniform slice spacing {:.2f}–{:.2f} mm", text.empty() ? "" : " and ", layout.minGap_mm,
                        layout.maxGap_mm);
  }
  return text;
}

}  // namespace

Result<std::vector<DicomSeriesSummary>> DicomSeriesReader::scan(const fs::path& folder) {
  DicomCodecs::ensureRegistered();
  auto contents = scanFolder(folder);
  if (!contents) return fail(contents.error());
  return summarize(groupBySeries(std::move(contents).value()));
}

Result<Volume> DicomSeriesReader::read(const fs::path& folder, const DicomSeriesReadOptions& options) {
  DicomCodecs::ensureRegistered();
  if (!std::isfinite(options.resampleSpacing_mm) || options.resampleSpacing_mm < 0.0) {
    return fail(fmt::format("resample spacing must be 0 (automatic) or a positive number of mm, got {}",
                            options.resampleSpacing_mm));
  }
  auto contents = scanFolder(folder);
  if (!contents) return fail(contents.error());
  auto series = groupBySeries(std::move(contents).value());
  const std::vector<DicomSeriesSummary> summaries = summarize(series);
  const std::string uid = options.seriesInstanceUid.empty() ? summaries.front().seriesInstanceUid
                                                            : options.seriesInstanceUid;
  const auto found = series.find(uid);
  if (found == series.end()) {
    return fail(fmt::format("series {} not found in {}; available: {}", uid, folder.string(), listSeries(summaries)));
  }
  std::vector<SliceHeader>& headers = found->second;
  auto stackResult = sortedSliceStack(headers);
  if (!stackResult) return fail(stackResult.error());
  SliceStack& stack = stackResult.value();
  const SliceStackLayout layout = stack.layout();
  const std::string irregularity = describeIrregularity(layout);
  if (!layout.isRegular() && options.policy == IrregularSeriesPolicy::Refuse) {
    return fail(fmt::format("series {} has {}, so its slices are not on a regular grid; read it with resampling "
                            "(the default policy, at the smallest slice gap or a spacing of your choice) or export it "
                            "from the scanner without tilt and gaps", uid, irregularity));
  }
  // Slices decode in parallel into their own planes; the first failing slice (in order) is reported.
  std::vector<Status> decoded(static_cast<std::size_t>(stack.sliceCount()), Ok{});
  tbb::parallel_for(0, stack.sliceCount(), [&](int k) {
    decoded[static_cast<std::size_t>(k)] = decodeSlice(headers[static_cast<std::size_t>(k)], stack.slice(k));
  });
  for (const Status& status : decoded) {
    if (!status) return fail(status.error());
  }

  const SliceHeader& first = headers.front();
  std::vector<std::string> warnings;
  if (summaries.size() > 1 && options.seriesInstanceUid.empty()) {
    warnings.push_back(fmt::format("{} holds {} image series; read the largest, {}. All: {}", folder.string(),
                                   summaries.size(), uid, listSeries(summaries)));
  }
  if (first.modality != "CT") {
    warnings.push_back(fmt::format("series {} has modality '{}', not CT: voxel values may not be Hounsfield units",
                                   uid, first.modality));
  }
  std::string description =
      fmt::format("DICOM series {} ({}{}, {} files) from {}", uid,
                  first.seriesDescription.empty() ? "" : "'" + first.seriesDescription + "', ", first.modality,
                  headers.size(), folder.string());
  Result<Volume> volume = fail("no volume");
  if (layout.isRegular()) {
    volume = std::move(stack).toVolume();
  } else {
    const double pixel_mm = stack.pixelSpacing_mm().minCoeff();
    const bool automatic = options.resampleSpacing_mm == 0.0;
    const bool gapBelowPixel = layout.minGap_mm < pixel_mm;
    const double spacing_mm = !automatic ? options.resampleSpacing_mm : std::max(layout.minGap_mm, pixel_mm);
    const float outside_hu = std::max(-1024.0f, stack.valueRange().first);
    volume = stack.resampled(spacing_mm, outside_hu);
    const std::string resampling = fmt::format(
        "{}: resampled onto a regular grid at {:.2f} mm slice spacing ({})", irregularity, spacing_mm,
        !automatic ? "as requested" : gapBelowPixel ? "automatic: the pixel spacing" : "automatic: the smallest slice gap");
    warnings.push_back(resampling);
    description += "; " + resampling;
  }
  if (!volume) return fail(fmt::format("series {}: {}", uid, volume.error()));
  volume.value().description = std::move(description);
  DicomIdentity identity = first.identity;
  identity.instances.clear();
  for (const SliceHeader& slice : headers) {
    identity.instances.insert(identity.instances.end(), slice.identity.instances.begin(), slice.identity.instances.end());
  }
  volume.value().dicom = std::move(identity);
  for (std::string& warning : warnings) volume.addWarning(std::move(warning));
  return volume;
}

}  // namespace fct
