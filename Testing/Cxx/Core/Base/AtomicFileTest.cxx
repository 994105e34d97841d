#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "Base/AtomicFile.h"
#include "TestSupport.h"

namespace fs = std::filesystem;
using fct::Status;

TEST(AtomicFile, WritesThePartsInOrderAndLeavesOnlyTheFile) {
  const fs::path dir = fct::test::scratchDir();
  const float values[2] = {1.0f, 2.0f};
  ASSERT_TRUE(fct::AtomicFile::write(dir / "a.bin", {"head", fct::AtomicFile::bytesOf(values, 2), "tail"}).ok());
  EXPECT_EQ(fct::test::readText(dir / "a.bin"),
            "head" + std::string(reinterpret_cast<const char*>(values), sizeof(values)) + "tail");
  EXPECT_EQ(fct::test::folderEntries(dir), std::vector<std::string>{"a.bin"});
}

TEST(AtomicFile, MissingFolderIsAnErrorNamingIt) {
  const fs::path dir = fct::test::scratchDir();
  const Status status = fct::AtomicFile::write(dir / "missing" / "a.txt", {"x"});
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.error().find("missing' does not exist"), std::string::npos) << status.error();
  EXPECT_TRUE(fct::test::folderEntries(dir).empty());
}
