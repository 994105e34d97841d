#pragma once
// The fuzz entry points: one function per loader a user feeds, taking the bytes of one input file. Each writes the
// bytes where the loader reads them (FuzzScratch) and calls the loader; the loader must return a value or an error
// message and never crash, hang or break its contract (a broken contract aborts). They are called by the libFuzzer
// programs of scripts/fuzz.sh and, in the normal build, by the CTest replay of Testing/Fuzz/regressions/<target>/.
// Every one returns 0 (libFuzzer's convention).

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "Drr/Transgraph.h"

namespace fct::fuzz {

/// Separates the files of one fuzz input for the multi-file DICOM series target.
inline constexpr std::string_view kFileSeparator = "FCTFUZZNEXTFILE";

/// One DICOM CT slice file as a one-file folder (DicomSeriesReader::scan and read; a series needs 2 slices, so this
/// stops after the header checks: fuzzDicomSeries reaches the pixel data).
int fuzzDicomSlice(const std::uint8_t* data, std::size_t size);
/// Several DICOM files (joined by kFileSeparator) as a folder: DicomSeriesReader::scan, then read of each series.
int fuzzDicomSeries(const std::uint8_t* data, std::size_t size);
/// A DICOM X-ray file (any transfer syntax DCMTK decodes): XrayDicomReader::readHeader, read of its first and last frame.
int fuzzXrayDicom(const std::uint8_t* data, std::size_t size);
/// A NIfTI-1 file (.nii.gz when the bytes start with the gzip magic, else .nii) through VolumeFileIO::read.
int fuzzNifti(const std::uint8_t* data, std::size_t size);
/// An NRRD file with attached data (.nrrd).
int fuzzNrrd(const std::uint8_t* data, std::size_t size);
/// An NRRD header (.nhdr) and its detached data file "fuzz.raw": the bytes before and after the first NUL byte.
int fuzzNhdr(const std::uint8_t* data, std::size_t size);
/// A MetaImage file with local data (.mha).
int fuzzMha(const std::uint8_t* data, std::size_t size);
/// A MetaImage header (.mhd) and its data file "fuzz.raw": the bytes before and after the first NUL byte.
int fuzzMhd(const std::uint8_t* data, std::size_t size);
/// A PNG X-ray image (XrayLoader).
int fuzzXrayPng(const std::uint8_t* data, std::size_t size);
/// A TIFF X-ray image (XrayLoader).
int fuzzXrayTiff(const std::uint8_t* data, std::size_t size);
/// A view file (ViewFile::read) beside the fixture images ap.png and lateral.png.
int fuzzViewFile(const std::uint8_t* data, std::size_t size);
/// A pose file (PoseFile::read).
int fuzzPoseFile(const std::uint8_t* data, std::size_t size);
/// A landmark file, read both as Slicer markups (LandmarkFile::readCt) and as X-ray clicks (readImage).
int fuzzLandmarkFile(const std::uint8_t* data, std::size_t size);
/// A landmark pair file (LandmarkPairFile::read) beside the fixture landmark files.
int fuzzLandmarkPairFile(const std::uint8_t* data, std::size_t size);
/// A registration preset file (RegistrationSchedule::readFile).
int fuzzPresetFile(const std::uint8_t* data, std::size_t size);
/// An ITK text transform (.tfm, ItkTransformFile::read).
int fuzzItkTransform(const std::uint8_t* data, std::size_t size);
/// A Transgraph cache file (TransgraphCache::load) with the key and layout of fixtureTransgraph().
int fuzzTransgraphCache(const std::uint8_t* data, std::size_t size);
/// A dewarp file (DewarpFile::read).
int fuzzDewarpFile(const std::uint8_t* data, std::size_t size);

/// The key of the Transgraph cache file that fuzzTransgraphCache loads.
inline constexpr std::uint64_t kTransgraphKey = 0x0123456789abcdefULL;
/// The layout (3 x 3 x 2 x 2 rays) that fuzzTransgraphCache expects; the seed writer saves a table of it.
TransgraphLayout transgraphLayout();

/// A target's name (the folder name under Testing/Fuzz/regressions/ and in scripts/fuzz.sh) and its entry point.
struct FuzzTarget {
  const char* name;
  int (*run)(const std::uint8_t* data, std::size_t size);
};
/// Every target of this library, in the order scripts/fuzz.sh runs them.
const std::vector<FuzzTarget>& loaderTargets();

}  // namespace fct::fuzz
