// Every writer of Core under a file-size limit (as on a full disk): the write fails with a message naming the file
// and the cause, the previous file stays byte for byte, and no temporary file is left behind.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <functional>
#include <string>
#include <vector>

#include "Base/JsonDocument.h"
#include "Base/TextFile.h"
#include "IO/Dicom/DicomRegistrationWriter.h"
#include "IO/Volume/VolumeFileIO.h"
#include "IO/Xray/ImageFileWriter.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using fct::Status;

/// A writer of one kind of file; `size` scales the content (the previous file is written with size 1).
struct Writer {
  std::string fileName;
  std::function<Status(const fs::path&, int size)> write;
};

fct::FloatImage image(int size) {
  fct::FloatImage drr;
  drr.cols = drr.rows = 16 * size;
  drr.pixels.assign(static_cast<std::size_t>(drr.cols) * drr.rows, 0.0f);
  for (std::size_t i = 0; i < drr.pixels.size(); ++i) drr.pixels[i] = static_cast<float>(i % 97) * 0.25f;
  return drr;
}

std::vector<Writer> writers() {
  return {
      {"RESULT.json",
       [](const fs::path& path, int size) {
         nlohmann::ordered_json result{{"pose", std::vector<double>(16 * size, 0.5)}, {"cancelled", false}};
         return fct::JsonDocument::write(result, path);
       }},
      {"trials.csv", [](const fs::path& path, int size) {
         return fct::TextFile::writeAtomically(path, std::string(100 * size, 'x'));
       }},
      {"drr.pfm", [](const fs::path& path, int size) { return fct::ImageFileWriter::writePfm(image(size), path); }},
      {"drr.tiff", [](const fs::path& path, int size) { return fct::ImageFileWriter::writeTiff(image(size), path); }},
      {"drr.png", [](const fs::path& path, int size) {
         return fct::ImageFileWriter::writePng16(image(size), path, 0.0f, 30.0f);
       }},
      {"drr.nrrd", [](const fs::path& path, int size) { return fct::ImageFileWriter::writeNrrd2d(image(size), path); }},
      {"ct.nrrd",
       [](const fs::path& path, int size) {
         auto ct = fct::Volume::create({8 * size, 8, 4}, {1.0, 1.0, 2.0});
         return ct ? fct::VolumeFileIO::write(ct.value(), path) : Status(fct::fail(ct.error()));
       }},
      {"reg.dcm",
       [](const fs::path& path, int size) {
         auto ct = fct::Volume::create({4, 4, 3}, {1, 1, 1});
         Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
         pose.translation() = Eigen::Vector3d(size, 2.0, 3.0);
         auto registration = fct::DicomRegistrationWriter::describe(ct.value(), pose, {});
         return registration ? fct::DicomRegistrationWriter::write(registration.value(), path)
                             : Status(fct::fail(registration.error()));
       }},
  };
}

}  // namespace

TEST(WriteFault, FileSizeLimitKeepsThePreviousFileOfEveryWriterAndSaysWhy) {
  for (const Writer& writer : writers()) {
    SCOPED_TRACE(writer.fileName);
    const fs::path dir = fct::test::scratchDir();
    const fs::path path = dir / writer.fileName;
    ASSERT_TRUE(writer.write(path, 1).ok());
    const std::string previous = fct::test::readText(path);
    Status status = fct::Ok{};
    {
      const fct::test::FileSizeLimit limit(64);  // smaller than any of the new files
      status = writer.write(path, 8);
    }
    ASSERT_FALSE(status.ok());
    EXPECT_NE(status.error().find(path.string()), std::string::npos) << status.error();
    EXPECT_NE(status.error().find("File too large"), std::string::npos) << status.error();
    EXPECT_EQ(fct::test::readText(path), previous);
    EXPECT_EQ(fct::test::folderEntries(dir), std::vector<std::string>{writer.fileName});
    // Without the limit the same write goes through and replaces the file.
    ASSERT_TRUE(writer.write(path, 8).ok());
    EXPECT_NE(fct::test::readText(path), previous);
  }
}
