// DicomRegistrationWriter / DicomRegistrationReader: the REG object round-trips the rigid matrix, passes dciodvfy
// (dicom3tools) without errors, refers to the CT and the X-rays, and bad input leaves the target untouched.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include "Base/TextFile.h"
#include "IO/Dicom/DicomRegistrationReader.h"
#include "IO/Dicom/DicomRegistrationWriter.h"
#include "SyntheticXrayDicom.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;
using fct::DicomRegistrationReader;
using fct::DicomRegistrationWriter;

Eigen::Isometry3d somePose() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(12.25, -7.5, 301.125);
  return T;
}

/// A small CT volume with the DICOM identity a series read from disk would carry.
fct::Volume dicomCt() {
  auto ct = fct::Volume::create({4, 4, 3}, {1, 1, 1});
  EXPECT_TRUE(ct) << ct.error();
  fct::DicomIdentity id;
  id.patientName = "Phantom^Pelvis";
  id.patientId = "FCT-0001";
  id.patientBirthDate = "19700101";
  id.patientSex = "O";
  id.studyInstanceUid = "1.2.826.0.1.3680043.9.9999.10";
  id.studyDate = "20261201";
  id.studyTime = "101500";
  id.studyId = "S1";
  id.accessionNumber = "A1";
  id.seriesInstanceUid = "1.2.826.0.1.3680043.9.9999.11";
  id.modality = "CT";
  id.frameOfReferenceUid = "1.2.826.0.1.3680043.9.9999.12";
  for (int k = 0; k < 3; ++k) {
    id.instances.push_back({UID_CTImageStorage, "1.2.826.0.1.3680043.9.9999.11." + std::to_string(k + 1)});
  }
  ct.value().dicom = id;
  return std::move(ct).value();
}

/// An XA file of another study with its own Frame of Reference (the C-arm's).
fs::path xrayOfAnotherStudy(const fs::path& path, const std::string& frameOfReferenceUid) {
  fct::test::SyntheticXray x;
  DcmFileFormat file = x.build();
  DcmDataset* ds = file.getDataset();
  ds->putAndInsertString(DCM_StudyInstanceUID, "1.2.826.0.1.3680043.9.9999.20");
  ds->putAndInsertString(DCM_SeriesInstanceUID, "1.2.826.0.1.3680043.9.9999.21");
  ds->putAndInsertString(DCM_FrameOfReferenceUID, frameOfReferenceUid.c_str());
  return fct::test::save(file, path);
}

/// dciodvfy's output for a file, or nullopt when dicom3tools is not installed.
std::optional<std::string> dciodvfy(const fs::path& path) {
  if (std::system("command -v dciodvfy > /dev/null 2>&1") != 0) return std::nullopt;
  const std::string command = "dciodvfy '" + path.string() + "' 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  if (!pipe) return std::nullopt;
  std::string output;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe.get())) output += buffer.data();
  return output;
}

/// The lines of dciodvfy's output that start with "Error".
std::string errorLines(const std::string& output) {
  std::istringstream in(output);
  std::string line, errors;
  while (std::getline(in, line)) {
    if (line.rfind("Error", 0) == 0) errors += line + "\n";
  }
  return errors;
}

}  // namespace

TEST(DicomRegistrationWriter, RoundTripsTheRigidMatrix) {
  const fs::path dir = fct::test::scratchDir();
  const std::string cArmFrame = "1.2.826.0.1.3680043.9.9999.30";
  const fs::path xray = xrayOfAnotherStudy(dir / "xa.dcm", cArmFrame);
  auto registration = DicomRegistrationWriter::describe(dicomCt(), somePose(), {xray});
  ASSERT_TRUE(registration) << registration.error();
  EXPECT_TRUE(registration.warnings().empty());
  EXPECT_EQ(registration.value().worldFrameOfReferenceUid, cArmFrame);  // the X-rays' frame is the world
  ASSERT_TRUE(DicomRegistrationWriter::write(registration.value(), dir / "reg.dcm").ok());

  auto read = DicomRegistrationReader::read(dir / "reg.dcm");
  ASSERT_TRUE(read) << read.error();
  EXPECT_TRUE(read.value().T_world_from_ct.matrix().isApprox(somePose().matrix(), 1e-9))
      << read.value().T_world_from_ct.matrix();
  EXPECT_EQ(read.value().ct.frameOfReferenceUid, "1.2.826.0.1.3680043.9.9999.12");
  EXPECT_EQ(read.value().worldFrameOfReferenceUid, cArmFrame);
  EXPECT_EQ(read.value().ct.patientId, "FCT-0001");
  EXPECT_EQ(read.value().ct.studyInstanceUid, "1.2.826.0.1.3680043.9.9999.10");
  EXPECT_EQ(read.value().ct.instances.size(), 3u);
  ASSERT_EQ(read.value().xrays.size(), 1u);
  EXPECT_EQ(read.value().xrays[0].instances.size(), 1u);

  // The identity: written and read back exactly.
  registration.value().T_world_from_ct = Eigen::Isometry3d::Identity();
  ASSERT_TRUE(DicomRegistrationWriter::write(registration.value(), dir / "identity.dcm").ok());
  auto identity = DicomRegistrationReader::read(dir / "identity.dcm");
  ASSERT_TRUE(identity) << identity.error();
  EXPECT_TRUE(identity.value().T_world_from_ct.matrix().isIdentity(0.0));
}

TEST(DicomRegistrationWriter, PassesDciodvfyWithoutErrors) {
  const fs::path dir = fct::test::scratchDir();
  auto withDicomCt = DicomRegistrationWriter::describe(
      dicomCt(), somePose(), {xrayOfAnotherStudy(dir / "xa.dcm", "1.2.826.0.1.3680043.9.9999.30")});
  ASSERT_TRUE(withDicomCt) << withDicomCt.error();
  ASSERT_TRUE(DicomRegistrationWriter::write(withDicomCt.value(), dir / "dicom_ct.dcm").ok());
  auto volumeOnly = fct::Volume::create({4, 4, 3}, {1, 1, 1});
  auto withFileCt = DicomRegistrationWriter::describe(volumeOnly.value(), somePose(), {});
  ASSERT_TRUE(withFileCt) << withFileCt.error();
  ASSERT_TRUE(DicomRegistrationWriter::write(withFileCt.value(), dir / "file_ct.dcm").ok());
  for (const char* name : {"dicom_ct.dcm", "file_ct.dcm"}) {
    const auto output = dciodvfy(dir / name);
    if (!output) GTEST_SKIP() << "dciodvfy (Debian package dicom3tools) is not installed; the REG object is unchecked";
    EXPECT_NE(output->find("SpatialRegistration"), std::string::npos) << *output;
    EXPECT_EQ(errorLines(*output), "") << name << ":\n" << *output;
  }
}

TEST(DicomRegistrationWriter, GivesANonDicomCtAGeneratedFrameOfReferenceWithAWarning) {
  auto ct = fct::Volume::create({4, 4, 3}, {1, 1, 1});
  auto registration = DicomRegistrationWriter::describe(ct.value(), somePose(), {});
  ASSERT_TRUE(registration) << registration.error();
  ASSERT_EQ(registration.warnings().size(), 1u);
  EXPECT_NE(registration.warnings()[0].find("generated Frame of Reference UID"), std::string::npos);
  EXPECT_FALSE(registration.value().ct.frameOfReferenceUid.empty());
  EXPECT_FALSE(registration.value().worldFrameOfReferenceUid.empty());
  EXPECT_NE(registration.value().ct.frameOfReferenceUid, registration.value().worldFrameOfReferenceUid);
  EXPECT_FALSE(registration.value().ct.studyInstanceUid.empty());
}

TEST(DicomRegistrationWriter, RefusesANonRigidPoseAndLeavesTheTargetUntouched) {
  const fs::path dir = fct::test::scratchDir();
  const fs::path target = dir / "reg.dcm";
  ASSERT_TRUE(fct::TextFile::writeAtomically(target, "previous result").ok());
  Eigen::Isometry3d scaled = somePose();
  scaled.linear() *= 1.1;
  auto refused = DicomRegistrationWriter::describe(dicomCt(), scaled, {});
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("not rigid"), std::string::npos) << refused.error();

  auto registration = DicomRegistrationWriter::describe(dicomCt(), somePose(), {});
  ASSERT_TRUE(registration) << registration.error();
  registration.value().T_world_from_ct = scaled;
  const fct::Status written = DicomRegistrationWriter::write(registration.value(), target);
  ASSERT_FALSE(written);
  EXPECT_EQ(fct::TextFile::read(target).value(), "previous result");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "no temporary file left";

  const fct::Status unwritable = DicomRegistrationWriter::write(registration.value(), dir / "missing" / "reg.dcm");
  EXPECT_FALSE(unwritable);
  auto unreadable = DicomRegistrationWriter::describe(dicomCt(), somePose(), {dir / "absent.dcm"});
  ASSERT_FALSE(unreadable);
  EXPECT_NE(unreadable.error().find("absent.dcm"), std::string::npos) << unreadable.error();
}

TEST(DicomRegistrationReader, RefusesFilesThatAreNotRegistrations) {
  const fs::path dir = fct::test::scratchDir();
  EXPECT_FALSE(DicomRegistrationReader::read(dir / "absent.dcm"));
  ASSERT_TRUE(fct::TextFile::writeAtomically(dir / "text.dcm", "not DICOM").ok());
  auto text = DicomRegistrationReader::read(dir / "text.dcm");
  ASSERT_FALSE(text);
  EXPECT_NE(text.error().find("not a readable DICOM file"), std::string::npos) << text.error();
  auto xa = DicomRegistrationReader::read(xrayOfAnotherStudy(dir / "xa.dcm", "1.2.3"));
  ASSERT_FALSE(xa);
  EXPECT_NE(xa.error().find("not a Spatial Registration object"), std::string::npos) << xa.error();
}
