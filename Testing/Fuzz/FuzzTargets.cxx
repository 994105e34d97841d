#include "FuzzTargets.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "FuzzScratch.h"
#include "Drr/TransgraphCache.h"
#include "IO/Dicom/DicomSeriesReader.h"
#include "IO/Dicom/XrayDicomReader.h"
#include "IO/Project/DewarpFile.h"
#include "IO/Project/ItkTransformFile.h"
#include "IO/Project/LandmarkFile.h"
#include "IO/Project/LandmarkPairFile.h"
#include "IO/Project/PoseFile.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/VolumeFileIO.h"
#include "IO/Xray/XrayLoader.h"
#include "Registration/RegistrationSchedule.h"

namespace fct::fuzz {
namespace fs = std::filesystem;

namespace {

/// A failed Result must say why; with FCT_FUZZ_VERBOSE set, prints what the loader said (for triage of an input).
template <typename T>
void explain(const Result<T>& result, const char* loader) {
  static const bool verbose = std::getenv("FCT_FUZZ_VERBOSE") != nullptr;
  if (verbose) std::fprintf(stderr, "%s: %s\n", loader, result.ok() ? "ok" : result.error().c_str());
  if (!result.ok() && result.error().empty()) {
    FuzzScratch::require(false, (std::string(loader) + " failed without a message").c_str());
  }
}

void checkVolume(const Result<Volume>& volume) {
  explain(volume, "volume loader");
  if (!volume) return;
  const Volume& v = volume.value();
  FuzzScratch::require(v.dims().minCoeff() > 0, "a loaded volume has an empty axis");
  FuzzScratch::require(v.voxelCount() == static_cast<std::size_t>(v.dims().x()) * v.dims().y() * v.dims().z(),
                       "a loaded volume's voxel count is not the product of its dims");
  FuzzScratch::require(v.spacing_mm().allFinite() && v.spacing_mm().minCoeff() > 0.0,
                       "a loaded volume has a non-positive or non-finite spacing");
  FuzzScratch::require(v.origin_lps_mm().allFinite() && v.direction_lps().allFinite(),
                       "a loaded volume has a non-finite origin or direction");
}

void checkXray(const Result<XrayImage>& image) {
  explain(image, "X-ray loader");
  if (!image) return;
  const XrayImage& x = image.value();
  FuzzScratch::require(x.cols > 0 && x.rows > 0, "a loaded X-ray has no pixels");
  FuzzScratch::require(x.pixels.size() == static_cast<std::size_t>(x.cols) * x.rows,
                       "a loaded X-ray's pixel count is not cols x rows");
  FuzzScratch::require(x.fovMask.empty() || x.fovMask.size() == x.pixels.size(),
                       "a loaded X-ray's field-of-view mask is not of its size");
}

void checkPose(const Result<Eigen::Isometry3d>& pose) {
  explain(pose, "pose loader");
  if (!pose) return;
  const Eigen::Matrix3d R = pose.value().linear();
  FuzzScratch::require(pose.value().matrix().allFinite(), "a loaded pose is not finite");
  FuzzScratch::require((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-3 && R.determinant() > 0.0,
                       "a loaded pose is not a rotation");
}

/// The bytes before the first NUL (a text header) and after it (its detached data).
std::pair<std::string_view, std::string_view> splitAtNul(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::size_t nul = bytes.find('\0');
  if (nul == std::string_view::npos) return {bytes, {}};
  return {bytes.substr(0, nul), bytes.substr(nul + 1)};
}

fs::path writeText(const std::string& name, std::string_view bytes) {
  return FuzzScratch::write(name, reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
}

int fuzzHeaderAndData(const std::string& headerName, const std::uint8_t* data, std::size_t size) {
  const auto [header, rawData] = splitAtNul(data, size);
  writeText("fuzz.raw", rawData);
  checkVolume(VolumeFileIO::read(writeText(headerName, header)));
  return 0;
}

/// A folder of its own (emptied) inside the scratch folder.
fs::path freshFolder(const std::string& name) {
  const fs::path folder = FuzzScratch::folder() / name;
  std::error_code ec;
  fs::remove_all(folder, ec);
  fs::create_directories(folder, ec);
  FuzzScratch::require(!ec, "cannot create a folder in the scratch folder");
  return folder;
}

}  // namespace

TransgraphLayout transgraphLayout() {
  TransgraphLayout layout;
  layout.origin_ct_mm = Eigen::Vector3d(1.0, -2.0, 3.0);
  layout.front_w_mm = -20.0;
  layout.back_w_mm = 20.0;
  layout.min_mm = Eigen::Vector4d(-10.0, -10.0, -2.0, -2.0);
  layout.step_mm = Eigen::Vector4d(10.0, 10.0, 4.0, 4.0);
  layout.counts = {3, 3, 2, 2};
  return layout;
}

int fuzzDicomSlice(const std::uint8_t* data, std::size_t size) {
  const fs::path folder = freshFolder("dicom_slice");
  FuzzScratch::write("dicom_slice/slice", data, size);
  explain(DicomSeriesReader::scan(folder), "DicomSeriesReader::scan");
  checkVolume(DicomSeriesReader::read(folder));
  return 0;
}

int fuzzDicomSeries(const std::uint8_t* data, std::size_t size) {
  const fs::path folder = freshFolder("dicom_series");
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  std::size_t start = 0;
  for (int n = 0; start <= bytes.size() && n < 8; ++n) {
    const std::size_t end = std::min(bytes.find(kFileSeparator, start), bytes.size());
    writeText("dicom_series/" + std::to_string(n) + ".dcm", bytes.substr(start, end - start));
    start = end + kFileSeparator.size();
  }
  const auto series = DicomSeriesReader::scan(folder);
  explain(series, "DicomSeriesReader::scan");
  if (!series) return 0;
  FuzzScratch::require(!series.value().empty(), "DicomSeriesReader::scan found no series without an error");
  for (const DicomSeriesSummary& summary : series.value()) {
    DicomSeriesReadOptions options;
    options.seriesInstanceUid = summary.seriesInstanceUid;
    checkVolume(DicomSeriesReader::read(folder, options));
  }
  return 0;
}

int fuzzXrayDicom(const std::uint8_t* data, std::size_t size) {
  const fs::path path = FuzzScratch::write("fuzz.dcm", data, size);
  const auto header = XrayDicomReader::readHeader(path);
  explain(header, "XrayDicomReader::readHeader");
  checkXray(XrayLoader::load(path, 0));
  if (header && header.value().frames > 1) checkXray(XrayLoader::load(path, header.value().frames - 1));
  return 0;
}

int fuzzNifti(const std::uint8_t* data, std::size_t size) {
  const bool gzipped = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
  checkVolume(VolumeFileIO::read(FuzzScratch::write(gzipped ? "fuzz.nii.gz" : "fuzz.nii", data, size)));
  return 0;
}

int fuzzNrrd(const std::uint8_t* data, std::size_t size) {
  checkVolume(VolumeFileIO::read(FuzzScratch::write("fuzz.nrrd", data, size)));
  return 0;
}

int fuzzNhdr(const std::uint8_t* data, std::size_t size) { return fuzzHeaderAndData("fuzz.nhdr", data, size); }

int fuzzMha(const std::uint8_t* data, std::size_t size) {
  checkVolume(VolumeFileIO::read(FuzzScratch::write("fuzz.mha", data, size)));
  return 0;
}

int fuzzMhd(const std::uint8_t* data, std::size_t size) { return fuzzHeaderAndData("fuzz.mhd", data, size); }

int fuzzXrayPng(const std::uint8_t* data, std::size_t size) {
  checkXray(XrayLoader::load(FuzzScratch::write("fuzz.png", data, size)));
  return 0;
}

int fuzzXrayTiff(const std::uint8_t* data, std::size_t size) {
  checkXray(XrayLoader::load(FuzzScratch::write("fuzz.tif", data, size)));
  return 0;
}

int fuzzViewFile(const std::uint8_t* data, std::size_t size) {
  const auto views = ViewFile::read(FuzzScratch::write("fuzz_views.json", data, size));
  explain(views, "ViewFile::read");
  if (views) FuzzScratch::require(!views.value().empty(), "ViewFile::read gave no view without an error");
  return 0;
}

int fuzzPoseFile(const std::uint8_t* data, std::size_t size) {
  checkPose(PoseFile::read(FuzzScratch::write("fuzz_pose.json", data, size)));
  return 0;
}

int fuzzLandmarkFile(const std::uint8_t* data, std::size_t size) {
  const fs::path path = FuzzScratch::write("fuzz.mrk.json", data, size);
  const auto ct = LandmarkFile::readCt(path);
  explain(ct, "LandmarkFile::readCt");
  if (ct) {
    for (const CtLandmark& landmark : ct.value())
      FuzzScratch::require(!landmark.name.empty() && landmark.p_ct_mm.allFinite(), "a CT landmark is unnamed or NaN");
  }
  const auto image = LandmarkFile::readImage(path);
  explain(image, "LandmarkFile::readImage");
  if (image) {
    for (const auto& [view, landmarks] : image.value())
      for (const ImageLandmark& landmark : landmarks)
        FuzzScratch::require(!landmark.name.empty() && landmark.uv_px.allFinite(), "an X-ray landmark is unnamed or NaN");
  }
  return 0;
}

int fuzzLandmarkPairFile(const std::uint8_t* data, std::size_t size) {
  const auto set = LandmarkPairFile::read(FuzzScratch::write("fuzz_pairs.json", data, size));
  explain(set, "LandmarkPairFile::read");
  return 0;
}

int fuzzPresetFile(const std::uint8_t* data, std::size_t size) {
  const auto schedule = RegistrationSchedule::readFile(FuzzScratch::write("fuzz_preset.json", data, size));
  explain(schedule, "RegistrationSchedule::readFile");
  return 0;
}

int fuzzItkTransform(const std::uint8_t* data, std::size_t size) {
  checkPose(ItkTransformFile::read(FuzzScratch::write("fuzz.tfm", data, size)));
  return 0;
}

int fuzzTransgraphCache(const std::uint8_t* data, std::size_t size) {
  const TransgraphLayout layout = transgraphLayout();
  const auto entry = TransgraphCache::load(FuzzScratch::write("fuzz.fctg", data, size), kTransgraphKey, layout);
  explain(entry, "TransgraphCache::load");
  if (entry) FuzzScratch::require(entry.value().table.size() == layout.rayCount(), "a loaded table has the wrong size");
  return 0;
}

int fuzzDewarpFile(const std::uint8_t* data, std::size_t size) {
  const auto dewarp = DewarpFile::read(FuzzScratch::write("fuzz.dewarp.json", data, size));
  explain(dewarp, "DewarpFile::read");
  if (dewarp) {
    const DewarpField& field = dewarp.value().field;
    FuzzScratch::require(field.ideal(Eigen::Vector2d(field.cols() / 2.0, field.rows() / 2.0)).allFinite(),
                         "a loaded dewarp field maps the image centre to a non-finite pixel");
  }
  return 0;
}

const std::vector<FuzzTarget>& loaderTargets() {
  static const std::vector<FuzzTarget> targets{
      {"dicom_slice", fuzzDicomSlice},   {"dicom_series", fuzzDicomSeries},
      {"xray_dicom", fuzzXrayDicom},     {"nifti", fuzzNifti},
      {"nrrd", fuzzNrrd},                {"nhdr", fuzzNhdr},
      {"mha", fuzzMha},                  {"mhd", fuzzMhd},
      {"xray_png", fuzzXrayPng},         {"xray_tiff", fuzzXrayTiff},
      {"view", fuzzViewFile},            {"pose", fuzzPoseFile},
      {"landmark", fuzzLandmarkFile},    {"landmark_pair", fuzzLandmarkPairFile},
      {"preset", fuzzPresetFile},        {"tfm", fuzzItkTransform},
      {"transgraph_cache", fuzzTransgraphCache}, {"dewarp", fuzzDewarpFile}};
  return targets;
}

}  // namespace fct::fuzz
