#include <dcmtk/dcmdata/dcxfer.h>
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "IO/Dicom/DicomElementLengthCheck.h"
#include "IO/Dicom/DicomSeriesReader.h"
#include "IO/Dicom/XrayDicomReader.h"
#include "DamagedDicom.h"
#include "SyntheticXrayDicom.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using fct::DicomElementLengthCheck;
using fct::test::Bytes;
using fct::test::implicitElement;
using fct::test::putU32;

Bytes readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const fs::path& path, const Bytes& bytes) {
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

/// A small X-ray saved by DCMTK in the Deflated Explicit VR Little Endian transfer syntax.
fs::path saveDeflatedXray(const fs::path& path) {
  DcmFileFormat file = fct::test::SyntheticXray{}.build();
  EXPECT_TRUE(file.saveFile(path.c_str(), EXS_DeflatedLittleEndianExplicit).good()) << path;
  return path;
}

/// The deflated file with the length of its Pixel Data element (7FE0,0010 OW) set to `length`, deflated again.
fs::path withPixelDataLength(const fs::path& deflated, std::uint32_t length, const fs::path& out) {
  const Bytes edited = fct::test::withDeflatedDatasetEdited(readBytes(deflated), [&](Bytes& dataset) {
    const std::size_t at = fct::test::find(dataset, fct::test::kExplicitPixelDataHeader);
    ASSERT_LT(at, dataset.size()) << "no Pixel Data element in the inflated dataset";
    fct::test::putU32(dataset, at + 8, length);
  });
  EXPECT_FALSE(edited.empty());
  writeBytes(out, edited);
  return out;
}

TEST(DicomElementLengthCheck, ADeflatedFileWrittenByDcmtkPassesAndLoads) {
  const fs::path path = saveDeflatedXray(fct::test::scratchDir() / "deflated.dcm");
  EXPECT_TRUE(DicomElementLengthCheck::check(path).ok()) << DicomElementLengthCheck::check(path).error();
  const auto image = fct::XrayDicomReader::read(path);
  ASSERT_TRUE(image.ok()) << image.error();
  EXPECT_EQ(image.value().cols, 5);
  EXPECT_EQ(image.value().rows, 4);
}

TEST(DicomElementLengthCheck, FilesWrittenByDcmtkInOtherSyntaxesAndNonDicomFilesPass) {
  const fs::path dir = fct::test::scratchDir();
  DcmFileFormat file = fct::test::SyntheticXray{}.build();
  for (const E_TransferSyntax syntax : {EXS_LittleEndianExplicit, EXS_LittleEndianImplicit, EXS_BigEndianExplicit}) {
    const fs::path path = dir / fmt::format("syntax{}.dcm", static_cast<int>(syntax));
    ASSERT_TRUE(file.saveFile(path.c_str(), syntax).good()) << path;
    const fct::Status checked = DicomElementLengthCheck::check(path);
    EXPECT_TRUE(checked.ok()) << DcmXfer(syntax).getXferName() << ": " << checked.error();
  }
  writeBytes(dir / "text.txt", Bytes{'h', 'e', 'l', 'l', 'o'});
  EXPECT_TRUE(DicomElementLengthCheck::check(dir / "text.txt").ok());
}

TEST(DicomElementLengthCheck, AnElementLongerThanTheInflatedDatasetIsRefusedByEveryDicomReader) {
  const fs::path dir = fct::test::scratchDir();
  const fs::path good = saveDeflatedXray(fct::test::workDir() / "good.dcm");
  // 3.2 GB declared in a file of well under a kilobyte: DCMTK alone would allocate it before finding the data short.
  const fs::path bad = withPixelDataLength(good, 0xC0000000u, dir / "bad.dcm");
  const fct::Status checked = DicomElementLengthCheck::check(bad);
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
  EXPECT_TRUE(DicomElementLengthCheck::check(fixed).ok()) << DicomElementLengthCheck::check(fixed).error();
}

/// Where `pattern` starts in bytes; fails the test when absent.
std::size_t find(const Bytes& bytes, const Bytes& pattern) {
  const std::size_t at = fct::test::find(bytes, pattern);
  EXPECT_LT(at, bytes.size()) << "pattern not found";
  return at;
}

constexpr std::uint32_t kDeclared = 4046797376u;  // the length of a fuzzed input: 4 GB declared, kilobytes present

/// Expects the check and the DICOM readers to refuse `path`, the check with a message holding `what` and the declared
/// length. The series scan only looks at Part 10 files (with 'DICM' at byte 128).
void expectRefused(const fs::path& path, const std::string& what, bool part10 = true) {
  const fct::Status checked = DicomElementLengthCheck::check(path);
  ASSERT_FALSE(checked.ok()) << path;
  EXPECT_NE(checked.error().find(what), std::string::npos) << checked.error();
  EXPECT_NE(checked.error().find(fmt::format("declares {} bytes", kDeclared)), std::string::npos) << checked.error();
  const auto xray = fct::XrayDicomReader::read(path);
  ASSERT_FALSE(xray.ok());
  EXPECT_NE(xray.error().find("declares"), std::string::npos) << xray.error();
  if (!part10) return;
  const auto series = fct::DicomSeriesReader::scan(path.parent_path());
  ASSERT_FALSE(series.ok());
  EXPECT_NE(series.error().find("declares"), std::string::npos) << series.error();
}

TEST(DicomElementLengthCheck, AnElementLongerThanTheFileIsRefusedInEveryUncompressedSyntax) {
  DcmFileFormat file = fct::test::SyntheticXray{}.build();
  struct Case {
    E_TransferSyntax syntax;
    Bytes pixelDataHeader;  // tag (and VR) as the syntax writes them
    std::size_t lengthAt;   // where the 32-bit length follows
    bool bigEndian;
  };
  const std::vector<Case> cases{{EXS_LittleEndianExplicit, {0xE0, 0x7F, 0x10, 0x00, 'O', 'W'}, 8, false},
                                {EXS_LittleEndianImplicit, {0xE0, 0x7F, 0x10, 0x00}, 4, false},
                                {EXS_BigEndianExplicit, {0x7F, 0xE0, 0x00, 0x10, 'O', 'W'}, 8, true}};
  for (const Case& c : cases) {
    SCOPED_TRACE(DcmXfer(c.syntax).getXferName());
    const fs::path dir = fct::test::scratchDir();
    const fs::path path = dir / "xray.dcm";
    ASSERT_TRUE(file.saveFile(path.c_str(), c.syntax).good());
    Bytes bytes = readBytes(path);
    putU32(bytes, find(bytes, c.pixelDataHeader) + c.lengthAt, kDeclared, c.bigEndian);
    writeBytes(path, bytes);
    expectRefused(path, "is a damaged DICOM file: element (7FE0,0010)");
  }
}

TEST(DicomElementLengthCheck, AFileWithoutATransferSyntaxIsWalkedInTheEncodingDcmtkGuesses) {
  // DCMTK reads a dataset that names no transfer syntax (a Part 10 file without (0002,0010), or no file meta
  // information at all) in the encoding its first element suggests: here implicit VR little endian.
  const Bytes dataset = [] {
    Bytes d = implicitElement(0x0008, 0x0016, 6, {'1', '.', '2', '.', '3', 0});
    const Bytes name = implicitElement(0x0010, 0x0010, kDeclared, Bytes(2000, 'A'));
    d.insert(d.end(), name.begin(), name.end());
    return d;
  }();
  const fs::path bareDir = fct::test::scratchDir();
  writeBytes(bareDir / "bare.dcm", dataset);
  expectRefused(bareDir / "bare.dcm", "read as a bare dataset its element (0010,0010) at byte 14 of the file", false);

  // The same dataset after a preamble and a file meta information group without a transfer syntax.
  Bytes part10(128, 0);
  for (const char c : std::string("DICM")) part10.push_back(static_cast<std::uint8_t>(c));
  const Bytes meta{0x02, 0x00, 0x01, 0x00, 'O', 'B', 0, 0, 2, 0, 0, 0, 0, 1};  // (0002,0001) version
  part10.insert(part10.end(), meta.begin(), meta.end());
  part10.insert(part10.end(), dataset.begin(), dataset.end());
  const fs::path part10Dir = fct::test::scratchDir();
  writeBytes(part10Dir / "part10.dcm", part10);
  expectRefused(part10Dir / "part10.dcm", "is a damaged DICOM file: element (0010,0010) at byte 160 of the file");
}

TEST(DicomElementLengthCheck, ElementsInsideSequencesAndUnknownVrItemsAreWalked) {
  // An explicit VR file with a private undefined-length UN element: DCMTK reads its items in implicit VR.
  DcmFileFormat file = fct::test::SyntheticXray{}.build();
  const fs::path dir = fct::test::scratchDir();
  const fs::path path = dir / "un.dcm";
  ASSERT_TRUE(file.saveFile(path.c_str(), EXS_LittleEndianExplicit).good());
  Bytes bytes = readBytes(path);
  const std::size_t pixelData = find(bytes, {0xE0, 0x7F, 0x10, 0x00, 'O', 'W'});
  Bytes un{0x09, 0x00, 0x10, 0x00, 'L', 'O', 4, 0, 'A', 'C', 'M', 'E',                      // (0009,0010) creator
           0x09, 0x00, 0x01, 0x10, 'U', 'N', 0, 0, 0xFF, 0xFF, 0xFF, 0xFF};                // (0009,1001) UN
  const Bytes item = implicitElement(0xFFFE, 0xE000, 0xFFFFFFFFu);
  const Bytes inner = implicitElement(0x0010, 0x0010, kDeclared, Bytes(64, 'A'));
  un.insert(un.end(), item.begin(), item.end());
  un.insert(un.end(), inner.begin(), inner.end());
  bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(pixelData), un.begin(), un.end());
  writeBytes(path, bytes);
  expectRefused(path, "is a damaged DICOM file: element (0010,0010)");

  // With the true length and the item and sequence closed the file passes the check again.
  const std::size_t innerAt = pixelData + 12 + 12 + 8;
  putU32(bytes, innerAt + 4, 64, false);
  const Bytes closing = [] {
    Bytes c = implicitElement(0xFFFE, 0xE00D, 0);
    const Bytes end = implicitElement(0xFFFE, 0xE0DD, 0);
    c.insert(c.end(), end.begin(), end.end());
    return c;
  }();
  bytes.insert(bytes.begin() + static_cast<std::ptrdiff_t>(innerAt + 8 + 64), closing.begin(), closing.end());
  writeBytes(path, bytes);
  const fct::Status fixed = DicomElementLengthCheck::check(path);
  EXPECT_TRUE(fixed.ok()) << fixed.error();
}

TEST(DicomElementLengthCheck, TheMetaInformationIsReadByItsGroupLengthAndUnknownVrsAsDcmtkDoes) {
  // A fuzzed input: an element of another group inside the file meta information's group length, before the
  // transfer syntax (DCMTK reads on to the group length and finds the deflated syntax), and in the deflated dataset
  // an element with the non-standard VR 'DX', to which DCMTK gives a 32-bit length, declaring 2.9 GB.
  const fs::path dir = fct::test::scratchDir();
  const fs::path good = saveDeflatedXray(fct::test::workDir() / "good.dcm");
  Bytes bytes = fct::test::withDeflatedDatasetEdited(readBytes(good), [](Bytes& dataset) {
    const std::size_t at = fct::test::find(dataset, fct::test::kExplicitPixelDataHeader);
    ASSERT_LT(at, dataset.size());
    Bytes element{0x18, 0x00, 0x10, 0x11, 'D', 'X', 0, 0, 0, 0, 0, 0};  // (0018,1110)
    putU32(element, 8, 2943721046u);
    dataset.insert(dataset.begin() + static_cast<std::ptrdiff_t>(at), element.begin(), element.end());
  });
  const std::size_t sopClass = find(bytes, {0x02, 0x00, 0x02, 0x00, 'U', 'I'});
  bytes[sopClass] = 0x42;  // (0002,0002) becomes (0042,0002)
  writeBytes(dir / "stray.dcm", bytes);
  const fct::Status checked = DicomElementLengthCheck::check(dir / "stray.dcm");
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.error().find("is a damaged deflated DICOM file: element (0018,1110)"), std::string::npos)
      << checked.error();
  EXPECT_NE(checked.error().find("declares 2943721046 bytes"), std::string::npos) << checked.error();
  EXPECT_FALSE(fct::XrayDicomReader::read(dir / "stray.dcm").ok());
}

TEST(DicomElementLengthCheck, AnOverlongFileMetaElementIsRefused) {
  DcmFileFormat file = fct::test::SyntheticXray{}.build();
  const fs::path dir = fct::test::scratchDir();
  const fs::path path = dir / "meta.dcm";
  ASSERT_TRUE(file.saveFile(path.c_str(), EXS_LittleEndianExplicit).good());
  Bytes bytes = readBytes(path);
  putU32(bytes, find(bytes, {0x02, 0x00, 0x01, 0x00, 'O', 'B'}) + 8, kDeclared, false);  // (0002,0001) version
  writeBytes(path, bytes);
  const fct::Status checked = DicomElementLengthCheck::check(path);
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.error().find("element (0002,0001) at byte 144 of its file meta information declares 4046797376"),
            std::string::npos)
      << checked.error();
}

TEST(DicomElementLengthCheck, AStreamThatDoesNotInflateIsRefused) {
  const fs::path path = saveDeflatedXray(fct::test::scratchDir() / "deflated.dcm");
  Bytes bytes = readBytes(path);
  const std::size_t metaEnd = fct::test::datasetStart(bytes);
  ASSERT_LT(metaEnd, bytes.size());
  std::fill(bytes.begin() + metaEnd, bytes.end(), std::uint8_t{0xFF});  // 0xFF: an invalid deflate block type
  writeBytes(path, bytes);
  const fct::Status checked = DicomElementLengthCheck::check(path);
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.error().find("does not inflate"), std::string::npos) << checked.error();
}

}  // namespace
