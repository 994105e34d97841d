#pragma once
// Helpers shared by the test programs: where the real data lives, scratch folders, running the CLI.

#include <filesystem>
#include <string>
#include <vector>

namespace fct::test {

/// The shared real-data folder: $FLUOROCT_DATA_DIR if set, else ../shared/data beside the source tree.
std::filesystem::path dataDir();
/// True if dataDir()/relative exists.
bool hasData(const std::string& relative);
/// The small files kept in the repository for the tests (Testing/Data), e.g. files written by earlier versions.
std::filesystem::path fixtureDir();
/// A fresh, empty scratch folder unique to the running test (removed and recreated on each call).
std::filesystem::path scratchDir();
/// A fresh, empty folder for this test's files beside scratchDir(), so a later scratchDir() call does not empty it.
std::filesystem::path workDir();
/// The whole text of a file; records a test failure and returns an empty string if it cannot be read.
std::string readText(const std::filesystem::path& path);
/// Path of the built `fluoroct` command-line program.
std::filesystem::path cliPath();
/// Path of a file or folder in the source tree, relative to its top, e.g. sourcePath("docs/evaluation/presets").
std::filesystem::path sourcePath(const std::string& relative);
/// Path of a script in the repository's scripts/ folder, e.g. scriptPath("study-parallel.sh").
std::filesystem::path scriptPath(const std::string& name);

/// Output of a finished process.
struct ProcessResult {
  int exitCode = -1;  ///< exit status, or -1 if it did not exit normally (signal)
  std::string out;    ///< captured stdout
  std::string err;    ///< captured stderr
};
/// Runs a shell command line (quoted by the caller) with no standard input and captures its output.
ProcessResult runCommand(const std::string& commandLine);
/// Runs `fluoroct` with the given argument string (shell-quoted by the caller) and captures its output.
ProcessResult runCli(const std::string& arguments);
/// Runs `fluoroct` like runCli in a child process whose files may not grow beyond `maxFileBytes` (RLIMIT_FSIZE, with
/// SIGXFSZ ignored, so a write past the limit fails with EFBIG like on a full disk).
ProcessResult runCliWithFileSizeLimit(const std::string& arguments, long maxFileBytes);

/// While alive, this process cannot write files larger than `maxFileBytes` (soft RLIMIT_FSIZE, SIGXFSZ ignored): every
/// write past the limit fails with EFBIG ("File too large"), as on a full disk. Restores both on destruction.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(long maxFileBytes);
  ~FileSizeLimit();
  FileSizeLimit(const FileSizeLimit&) = delete;
  FileSizeLimit& operator=(const FileSizeLimit&) = delete;

 private:
  unsigned long long m_previousSoftLimit;
  void (*m_previousHandler)(int);
};

/// The names of the entries of `folder`, sorted (to check that a failed write left no temporary file behind).
std::vector<std::string> folderEntries(const std::filesystem::path& folder);

}  // namespace fct::test

/// Skips the current test with a message when a file or folder of the shared data is absent.
#define FCT_REQUIRE_DATA(relative)                                                                   \
  do {                                                                                               \
    if (!::fct::test::hasData(relative)) {                                                           \
      GTEST_SKIP() << "shared data '" << (relative) << "' not found under " << ::fct::test::dataDir() \
                   << " (set FLUOROCT_DATA_DIR)";                                                    \
    }                                                                                                \
  } while (0)
