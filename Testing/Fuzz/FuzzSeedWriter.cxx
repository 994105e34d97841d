#include "FuzzSeedWriter.h"

#include <fmt/core.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "FuzzScratch.h"
#include "FuzzTargets.h"
#include "Drr/TransgraphCache.h"
#include "IO/Project/DewarpFile.h"
#include "IO/Project/ItkTransformFile.h"
#include "IO/Project/PoseFile.h"
#include "IO/Volume/MetaImageFormat.h"
#include "IO/Volume/NrrdFormat.h"
#include "IO/Volume/VolumeFileIO.h"
#include "IO/Xray/ImageFileWriter.h"
#include "IO/Xray/XrayLoader.h"
#include "Registration/RegistrationSchedule.h"
#include "DamagedDicom.h"
#include "SyntheticCtDicom.h"
#include "SyntheticXrayDicom.h"
#include "TinyTiff.h"

namespace fct::fuzz {
namespace fs = std::filesystem;

namespace {

Status writeBytes(const fs::path& path, const std::string& bytes) {
  std::error_code ec;
  fs::create_directories(path.parent_path(), ec);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
  out.close();
  if (!out) return fail(fmt::format("cannot write the seed {}", path.string()));
  return Ok{};
}

Status copySeed(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::create_directories(to.parent_path(), ec);
  fs::copy_file(from, to, fs::copy_options::overwrite_existing, ec);
  if (ec) return fail(fmt::format("cannot copy the seed {} to {}: {}", from.string(), to.string(), ec.message()));
  return Ok{};
}

std::string voxelBytes(const Volume& volume) {
  const auto& voxels = volume.voxels();
  return std::string(reinterpret_cast<const char*>(voxels.data()), voxels.size() * sizeof(float));
}

/// A header + NUL + data seed of the .nhdr / .mhd targets.
std::string detached(const std::string& header, const Volume& volume) {
  return header + std::string(1, '\0') + voxelBytes(volume);
}

Status writeVolumeSeeds(const fs::path& root) {
  const fs::path scratch = FuzzScratch::folder();
  auto ct = VolumeFileIO::read(scratch / FuzzScratch::kCtFile);
  if (!ct) return fail(ct.error());
  const Volume& volume = ct.value();
  for (const auto& [target, file] : std::vector<std::pair<std::string, std::string>>{{"nrrd", "ct.nrrd"},
                                                                                    {"mha", "ct.mha"}}) {
    if (Status written = VolumeFileIO::write(volume, root / target / file); !written) return written;
  }
  std::string nhdr = NrrdFormat::header(volume);
  nhdr.insert(nhdr.size() - 1, "data file: fuzz.raw\n");  // before the closing blank line
  if (Status written = writeBytes(root / "nhdr" / "ct.nhdr", detached(nhdr, volume)); !written) return written;
  return writeBytes(root / "mhd" / "ct.mhd", detached(MetaImageFormat::header(volume, "fuzz.raw"), volume));
}

Status writeImageSeeds(const fs::path& root) {
  const fs::path scratch = FuzzScratch::folder();
  if (Status copied = copySeed(scratch / "ap.png", root / "xray_png" / "ap.png"); !copied) return copied;
  auto image = XrayLoader::load(scratch / "lateral.png");
  if (!image) return fail(image.error());
  const FloatImage pixels{image.value().cols, image.value().rows, image.value().pixels};
  if (Status written = ImageFileWriter::writeTiff(pixels, root / "xray_tiff" / "lateral.tif"); !written) return written;
  return ImageFileWriter::writePng16(pixels, root / "xray_png" / "lateral_window.png", 1000.0f, 40000.0f);
}

Status writeProjectSeeds(const fs::path& root) {
  const fs::path scratch = FuzzScratch::folder();
  for (const auto& [target, file] : std::vector<std::pair<std::string, std::string>>{
           {"view", FuzzScratch::kViewFile},
           {"landmark", FuzzScratch::kCtLandmarkFile},
           {"landmark", FuzzScratch::kImageLandmarkFile}}) {
    if (Status copied = copySeed(scratch / file, root / target / file); !copied) return copied;
  }
  for (const char* method : {"reprojection", "triangulation"}) {
    const std::string pairs = fmt::format(R"({{"ct": "{}", "image": "{}", "method": "{}"}})",
                                          FuzzScratch::kCtLandmarkFile, FuzzScratch::kImageLandmarkFile, method);
    if (Status written = writeBytes(root / "landmark_pair" / (std::string(method) + ".json"), pairs); !written) {
      return written;
    }
  }
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  T_world_from_ct.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  T_world_from_ct.translation() = Eigen::Vector3d(5.0, -4.0, 6.0);
  if (Status written = PoseFile::write(T_world_from_ct, root / "pose" / "pose.json"); !written) return written;
  if (Status written = ItkTransformFile::write(T_world_from_ct, root / "tfm" / "pose.tfm"); !written) return written;
  for (const std::string& name : RegistrationSchedule::builtinNames()) {
    auto schedule = RegistrationSchedule::builtin(name);
    if (!schedule) return fail(schedule.error());
    if (Status written = writeBytes(root / "preset" / (name + ".json"), schedule.value().toJson().dump(2)); !written) {
      return written;
    }
  }
  return Ok{};
}

Status writeBinarySeeds(const fs::path& root) {
  const TransgraphLayout layout = transgraphLayout();
  std::vector<float> table(layout.rayCount());
  for (std::size_t n = 0; n < table.size(); ++n) table[n] = 0.5f * static_cast<float>(n);
  if (Status saved = TransgraphCache::save(root / "transgraph_cache" / "table.fctg", kTransgraphKey, layout, table);
      !saved) {
    return saved;
  }
  const int degree = 3;
  const auto termCount = static_cast<Eigen::Index>(DewarpField::terms(degree).size());
  Eigen::VectorXd colCoefficients = Eigen::VectorXd::Zero(termCount), rowCoefficients = colCoefficients;
  colCoefficients[1] = 0.4;
  rowCoefficients[2] = -0.3;
  auto field = DewarpField::create(16, 12, degree, colCoefficients, rowCoefficients);
  if (!field) return fail(field.error());
  DewarpFileContents contents{field.value(), {}};
  contents.calibration.gridImage = "grid.png";
  contents.calibration.pitch_mm = 10.0;
  contents.calibration.beadCount = 12;
  return DewarpFile::write(contents, root / "dewarp" / "field.dewarp.json");
}

/// A DICOM file as DCMTK saves the dataset in `syntax`, as bytes, through a file beside `scratch`.
Result<test::Bytes> savedBytes(DcmFileFormat& file, E_TransferSyntax syntax, const fs::path& scratch) {
  if (!file.saveFile(scratch.c_str(), syntax).good()) {
    return fail(fmt::format("cannot write the DICOM seed {}", scratch.string()));
  }
  std::ifstream in(scratch, std::ios::binary);
  test::Bytes bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  std::error_code ec;
  fs::remove(scratch, ec);
  return bytes;
}

/// The bytes of a DICOM file as DCMTK saves the dataset (Explicit VR Little Endian), through a file beside `scratch`.
Result<std::string> dicomBytes(DcmFileFormat& file, const fs::path& scratch) {
  auto bytes = savedBytes(file, EXS_LittleEndianExplicit, scratch);
  if (!bytes) return fail(bytes.error());
  return std::string(bytes.value().begin(), bytes.value().end());
}

/// A dicom_series input: the slices' files joined by kFileSeparator.
Result<std::string> seriesBytes(const std::vector<test::SyntheticSlice>& slices, const fs::path& scratch) {
  std::string joined;
  for (const test::SyntheticSlice& slice : slices) {
    DcmFileFormat file = slice.build();
    auto bytes = dicomBytes(file, scratch);
    if (!bytes) return fail(bytes.error());
    if (!joined.empty()) joined += kFileSeparator;
    joined += bytes.value();
  }
  return joined;
}

/// The inputs of the DICOM reader defects whose elements declared gigabytes in files of kilobytes: an X-ray and a CT
/// slice in implicit VR little endian whose Pixel Data declares 4,046,797,376 bytes, and a deflated X-ray whose meta
/// information holds an element of another group and whose dataset holds (0018,1110) with the non-standard VR 'DX'
/// declaring 2,943,721,046 bytes.
Status writeOverlongElementSeeds(const fs::path& root, const fs::path& scratch) {
  const test::Bytes implicitPixelData{0xE0, 0x7F, 0x10, 0x00};
  DcmFileFormat xray = test::SyntheticXray{}.build();
  DcmFileFormat slice = test::SyntheticSlice{}.build();
  for (const auto& [file, name] : {std::pair{&xray, "xray_dicom/pixel_data_longer_than_the_file.dcm"},
                                   std::pair{&slice, "dicom_slice/pixel_data_longer_than_the_file.dcm"}}) {
    auto bytes = savedBytes(*file, EXS_LittleEndianImplicit, scratch);
    if (!bytes) return fail(bytes.error());
    const std::size_t at = test::find(bytes.value(), implicitPixelData);
    if (at >= bytes.value().size()) return fail(fmt::format("no Pixel Data in the seed {}", name));
    test::putU32(bytes.value(), at + 4, 4046797376u);
    if (Status written = writeBytes(root / name, std::string(bytes.value().begin(), bytes.value().end())); !written) {
      return written;
    }
  }
  auto deflated = savedBytes(xray, EXS_DeflatedLittleEndianExplicit, scratch);
  if (!deflated) return fail(deflated.error());
  test::Bytes stray = test::withDeflatedDatasetEdited(deflated.value(), [](test::Bytes& dataset) {
    const std::size_t at = std::min(test::find(dataset, test::kExplicitPixelDataHeader), dataset.size());
    test::Bytes element{0x18, 0x00, 0x10, 0x11, 'D', 'X', 0, 0, 0, 0, 0, 0};  // (0018,1110)
    test::putU32(element, 8, 2943721046u);
    dataset.insert(dataset.begin() + static_cast<std::ptrdiff_t>(at), element.begin(), element.end());
  });
  const std::size_t sopClass = test::find(stray, {0x02, 0x00, 0x02, 0x00, 'U', 'I'});
  if (stray.empty() || sopClass >= stray.size()) return fail("cannot make the deflated seed with a stray meta element");
  stray[sopClass] = 0x42;  // (0002,0002) becomes (0042,0002)
  return writeBytes(root / "xray_dicom" / "deflated_unknown_vr_declares_gigabytes.dcm",
                    std::string(stray.begin(), stray.end()));
}

/// DICOM inputs made with DCMTK: a 16x16 DX with C-arm tags, a 2-slice CT series, and the series of the loader defect
/// fuzzing found (3 tilted slices, the last moved 12.5 km in-plane, whose resampled grid would hold gigabytes).
Status writeDicomSeeds(const fs::path& root) {
  const fs::path scratch = root / "dicom_seed.tmp";
  test::SyntheticXray dx;
  dx.modality = "DX";
  dx.cols = dx.rows = 16;
  for (int n = 0; n < dx.cols * dx.rows; ++n) dx.samples.push_back(static_cast<Uint16>(1000 + 37 * n));
  DcmFileFormat dxFile = dx.build();
  test::putCarmTags(*dxFile.getDataset(), 1000.0, 600.0, 0.3, 0.3, 10.0, -5.0);
  auto dxBytes = dicomBytes(dxFile, scratch);
  if (!dxBytes) return fail(dxBytes.error());
  if (Status written = writeBytes(root / "xray_dicom" / "dx_16px.dcm", dxBytes.value()); !written) return written;

  test::SyntheticSlice slice;
  slice.cols = slice.rows = 16;
  slice.stored = [](int i, int j) { return 40 * i - 25 * j; };
  std::vector<test::SyntheticSlice> pair(2, slice);
  pair[1].ipp_lps_mm.z() = 2.5;
  auto pairBytes = seriesBytes(pair, scratch);
  if (!pairBytes) return fail(pairBytes.error());
  if (Status written = writeBytes(root / "dicom_series" / "two_slices_16px.bin", pairBytes.value()); !written) {
    return written;
  }

  test::SyntheticSlice tilted;
  tilted.cols = tilted.rows = 32;
  tilted.rowSpacing_mm = tilted.columnSpacing_mm = 7.8125;
  tilted.sliceThickness_mm = 4.0;
  tilted.iop = {1, 0, 0, 0, 0.9483237, -0.3173047};
  std::vector<test::SyntheticSlice> farApart(3, tilted);
  farApart[0].ipp_lps_mm = Eigen::Vector3d(-125.0, -123.5404569, 5.8360586);
  farApart[1].ipp_lps_mm = Eigen::Vector3d(-125.0, -323.5404569, 10.0560586);
  farApart[2].ipp_lps_mm = Eigen::Vector3d(-12500000.0, -123.5404569, 14.2760586);
  auto farBytes = seriesBytes(farApart, scratch);
  if (!farBytes) return fail(farBytes.error());
  const fs::path farPath = root / "dicom_series" / "slice_positions_far_apart.bin";
  if (Status written = writeBytes(farPath, farBytes.value()); !written) return written;
  return writeOverlongElementSeeds(root, scratch);
}

/// A 6x5x4 int16 NIfTI-1 single file (1 mm voxels, no orientation codes) whose data starts at `voxOffset`.
std::string niftiBytes(float voxOffset) {
  std::string bytes(352 + 6 * 5 * 4 * sizeof(std::int16_t), '\0');
  const auto put = [&bytes](std::size_t at, const void* value, std::size_t size) { std::memcpy(&bytes[at], value, size); };
  const std::int32_t headerSize = 348;
  const std::int16_t dim[8] = {3, 6, 5, 4, 1, 1, 1, 1}, datatypeInt16 = 4, bitsPerVoxel = 16;
  const float pixdim[8] = {1, 1, 1, 1, 0, 0, 0, 0}, slope = 1.0f;
  put(0, &headerSize, sizeof headerSize);
  put(40, dim, sizeof dim);
  put(70, &datatypeInt16, sizeof datatypeInt16);
  put(72, &bitsPerVoxel, sizeof bitsPerVoxel);
  put(76, pixdim, sizeof pixdim);
  put(108, &voxOffset, sizeof voxOffset);
  put(112, &slope, sizeof slope);
  put(344, "n+1", 4);
  return bytes;
}

/// Small inputs written from their description: a NIfTI seed, and the inputs of the loader defects fuzzing found
/// (a NIfTI vox_offset beyond the file, NRRD and MetaImage sizes beyond int, a TIFF declaring 60000 x 40000 pixels).
Status writeCraftedSeeds(const fs::path& root) {
  const std::string data(64, '\x11');
  for (const auto& [file, bytes] : std::vector<std::pair<std::string, std::string>>{
           {"nifti/int16_6x5x4.nii", niftiBytes(352.0f)},
           {"nifti/vox_offset_beyond_the_file.nii", niftiBytes(5.4e8f)},
           {"xray_tiff/declares_60000x40000_pixels.tif", test::tinyTiff(60000, 40000, false, false)},
           {"nrrd/sizes_beyond_int.nrrd", "NRRD0004\ntype: short\ndimension: 3\nspace: left-posterior-superior\n"
                                          "sizes: 10 8 777777777777777777777777777778\nencoding: raw\n\n" + data},
           {"mha/dimsize_beyond_int.mha", "ObjectType = Image\nNDims = 3\nBinaryData = True\nElementSpacing = 1 1 2\n"
                                          "DimSize = 11111111111111111111111111110 6 8\nElementType = MET_SHORT\n"
                                          "ElementDataFile = LOCAL\n" + data}}) {
    if (Status written = writeBytes(root / file, bytes); !written) return written;
  }
  return Ok{};
}

}  // namespace

Status writeLoaderSeeds(const fs::path& root) {
  for (const FuzzTarget& target : loaderTargets()) {
    std::error_code ec;
    fs::create_directories(root / target.name, ec);
    if (ec) return fail(fmt::format("cannot create the seed folder {}: {}", (root / target.name).string(), ec.message()));
  }
  for (Status (*write)(const fs::path&) : {writeVolumeSeeds, writeImageSeeds, writeProjectSeeds, writeBinarySeeds, writeCraftedSeeds,
                                             writeDicomSeeds}) {
    if (Status written = write(root); !written) return written;
  }
  return Ok{};
}

}  // namespace fct::fuzz
