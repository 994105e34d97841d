#include <gtest/gtest.h>

#include "Base/TextFile.h"
#include "TestSupport.h"

TEST(TextFile, WritesAtomicallyAndReadsBack) {
  const auto dir = fct::test::scratchDir();
  const auto path = dir / "a.txt";
  ASSERT_TRUE(fct::TextFile::writeAtomically(path, "first\n").ok());
  ASSERT_TRUE(fct::TextFile::writeAtomically(path, std::string("second\0binary", 13)).ok());
  EXPECT_EQ(fct::TextFile::read(path).value(), std::string("second\0binary", 13));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);
}

TEST(TextFile, FailuresNameThePathAndLeaveNoTemporaryFile) {
  const auto dir = fct::test::scratchDir();
  std::filesystem::create_directory(dir / "folder");
  std::filesystem::create_directory(dir / "folder" / "inside");
  auto status = fct::TextFile::writeAtomically(dir / "folder", "x");  // a non-empty folder cannot be replaced
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("cannot replace"), std::string::npos) << status.error();
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);
  status = fct::TextFile::writeAtomically(dir / "missing" / "a.txt", "x");
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("missing/a.txt"), std::string::npos) << status.error();
  auto read = fct::TextFile::read(dir / "nope.txt");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("nope.txt' not found"), std::string::npos) << read.error();
  read = fct::TextFile::read(dir / "folder");
  ASSERT_FALSE(read.ok());
  EXPECT_NE(read.error().find("is a folder"), std::string::npos) << read.error();
}
