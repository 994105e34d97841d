#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "IO/Dicom/DeflatedDatasetCheck.h"
#include "IO/Dicom/DicomSeriesReader.h"
#include "IO/Dicom/XrayDicomReader.h"
#include "SyntheticXrayDicom.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using fct::DeflatedDatasetCheck;
using Bytes = std::vector<std::uint8_t>;

Bytes readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const fs::path& path, const Bytes& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

/// Raw deflate (no zlib header) or inflate of bytes, as the Deflated transfer syntax stores its dataset.
Bytes zlibRaw(const Bytes& in, bool compress) {
  z_stream z{};
  if (compress) {
    EXPECT_EQ(deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY), Z_OK);
  } else {
    EXPECT_EQ(inflateInit2(&z, -MAX_WBITS), Z_OK);
  }
  Bytes out;
  std::array<std::uint8_t, 4096> chunk{};
  z.next_in = const_cast<Bytef*>(in.data());
  z.avail_in = static_cast<uInt>(in.size());
  int status = Z_OK;
  while (status == Z_OK) {
    z.next_out = chunk.data();
    z.avail_out = static_cast<uInt>(chunk.size());
    status = compress ? deflate(&z, Z_FINISH) : inflate(&z, Z_NO_FLUSH);
    out.insert(out.end(), chunk.data(), chunk.data() + (chunk.size() - z.avail_out));
  }
  EXPECT_EQ(status, Z_STREAM_END);
  compress ? deflateEnd(&z) : inflateEnd(&z);
  return out;
}

/// Where the deflated dataset starts: after the preamble and "DICM" (132 bytes) comes (0002,0000) UL, whose 4-byte
/// value is the length of the rest of group 0002.
std::size_t datasetStart(const Bytes& bytes) {
  return 144 + (bytes[140] | bytes[141] << 8 | bytes[142] << 16 | std::size_t{bytes[143]} << 24);
}

/// A small X-ray saved by DCMTK in the Deflated Explicit VR Little Endian transfer syntax.
fs::path saveDeflatedXray(const fs::path& path) {
  DcmFileFormat file = fct::test::SyntheticXray{}.build();
  EXPECT_TRUE(file.saveFile(path.c_str(), EXS_DeflatedLittleEndianExplicit).good()) << path;
  return path;
}

/// The deflated file with the length of its Pixel Data element (7FE0,0010 OW) set to `length`, deflated again.
fs::path withPixelDataLength(const fs::path& deflated, std::uint32_t length, const fs::path& out) {
  const Bytes bytes = readBytes(deflated);
  const std::size_t metaEnd = datasetStart(bytes);
  Bytes dataset = zlibRaw(Bytes(bytes.begin() + metaEnd, bytes.end()), false);
  const std::array<std::uint8_t, 6> pixelData{0xE0, 0x7F, 0x10, 0x00, 'O', 'W'};
  const auto at = std::search(dataset.begin(), dataset.end(), pixelData.begin(), pixelData.end());
  EXPECT_NE(at, dataset.end()) << "no Pixel Data element in the inflated dataset";
  if (at == dataset.end()) return out;
  for (int i = 0; i < 4; ++i) at[8 + i] = static_cast<std::uint8_t>(length >> (8 * i));
  Bytes file(bytes.begin(), bytes.begin() + metaEnd);
  const Bytes again = zlibRaw(dataset, true);
  file.insert(file.end(), again.begin(), again.end());
  writeBytes(out, file);
  return out;
}

TEST(DeflatedDatasetCheck, ADeflatedFileWrittenByDcmtkPassesAndLoads) {
  const fs::path path = saveDeflatedXray(fct::test::scratchDir() / "deflated.dcm");
  EXPECT_TRUE(DeflatedDatasetCheck::check(path).ok()) << DeflatedDatasetCheck::check(path).error();
  const auto image = fct::XrayDicomReader::read(path);
  ASSERT_TRUE(image.ok()) << image.error();
  EXPECT_EQ(image.value().cols, 5);
  EXPECT_EQ(image.value().rows, 4);
}

TEST(DeflatedDatasetCheck, FilesInOtherSyntaxesAndNonDicomFilesPass) {
  const fs::path dir = fct::test::scratchDir();
  DcmFileFormat file = fct::test::SyntheticXray{}.build();
  EXPECT_TRUE(DeflatedDatasetCheck::check(fct::test::save(file, dir / "explicit.dcm")).ok());
  writeBytes(dir / "text.txt", Bytes{'h', 'e', 'l', 'l', 'o'});
  EXPECT_TRUE(DeflatedDatasetCheck::check(dir / "text.txt").ok());
}

TEST(DeflatedDatasetCheck, AnElementLongerThanTheInflatedDatasetIsRefusedByEveryDicomReader) {
  const fs::path dir = fct::test::scratchDir();
  const fs::path good = saveDeflatedXray(fct::test::workDir() / "good.dcm");
  // 3.2 GB declared in a file of well under a kilobyte: DCMTK alone would allocate it before finding the data short.
  const fs::path bad = withPixelDataLength(good, 0xC0000000u, dir / "bad.dcm");
  const fct::Status checked = DeflatedDatasetCheck::check(bad);
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.error().find("element (7FE0,0010)"), std::string::npos) << checked.error();
  EXPECT_NE(checked.error().find("declares 3221225472 bytes"), std::string::npos) << checked.error();
  EXPECT_NE(checked.error().find("'bad.dcm' is a damaged deflated DICOM file"), std::string::npos) << checked.error();

  const auto xray = fct::XrayDicomReader::read(bad);
  ASSERT_FALSE(xray.ok());
  EXPECT_NE(xray.error().find("declares 3221225472 bytes"), std::string::npos) << xray.error();
  const auto series = fct::DicomSeriesReader::scan(dir);
  ASSERT_FALSE(series.ok());
  EXPECT_NE(series.error().find("declares 3221225472 bytes"), std::string::npos) << series.error();

  // The same file with the true length passes again: the check reads the lengths, not the syntax alone.
  const fs::path fixed = withPixelDataLength(good, 5 * 4 * 2, dir / "fixed.dcm");
  EXPECT_TRUE(DeflatedDatasetCheck::check(fixed).ok()) << DeflatedDatasetCheck::check(fixed).error();
}

TEST(DeflatedDatasetCheck, AStreamThatDoesNotInflateIsRefused) {
  const fs::path path = saveDeflatedXray(fct::test::scratchDir() / "deflated.dcm");
  Bytes bytes = readBytes(path);
  const std::size_t metaEnd = datasetStart(bytes);
  ASSERT_LT(metaEnd, bytes.size());
  std::fill(bytes.begin() + metaEnd, bytes.end(), std::uint8_t{0xFF});  // 0xFF: an invalid deflate block type
  writeBytes(path, bytes);
  const fct::Status checked = DeflatedDatasetCheck::check(path);
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.error().find("does not inflate"), std::string::npos) << checked.error();
}

}  // namespace
