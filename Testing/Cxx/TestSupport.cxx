#include "TestSupport.h"

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace fct::test {

std::filesystem::path dataDir() {
  if (const char* env = std::getenv("FLUOROCT_DATA_DIR"); env && *env) return env;
  return FCT_DEFAULT_DATA_DIR;
}

bool hasData(const std::string& relative) { return std::filesystem::exists(dataDir() / relative); }

std::filesystem::path fixtureDir() { return FCT_FIXTURE_DIR; }

std::filesystem::path scratchDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? fmt::format("{}_{}", info->test_suite_name(), info->name()) : "fct_test";
  for (char& c : name) {
    if (c == '/') c = '_';
  }
  const auto dir = std::filesystem::temp_directory_path() / "fluoroct_tests" / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::filesystem::path workDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const auto dir = scratchDir().parent_path() / (std::string(info ? info->name() : "fct_test") + "_files");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string readText(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::filesystem::path cliPath() { return FCT_CLI_PATH; }

std::filesystem::path sourcePath(const std::string& relative) { return std::filesystem::path(FCT_SOURCE_DIR) / relative; }

std::filesystem::path scriptPath(const std::string& name) { return sourcePath("scripts") / name; }

ProcessResult runCommand(const std::string& commandLine) {
  // Not scratchDir(): that would empty the calling test's folder before every command.
  const auto dir = std::filesystem::temp_directory_path() / "fluoroct_tests" / "cli_capture";
  std::filesystem::create_directories(dir);
  const auto outPath = dir / fmt::format("out_{}.txt", ::getpid());
  const auto errPath = dir / fmt::format("err_{}.txt", ::getpid());
  const std::string command =
      fmt::format("{} > '{}' 2> '{}' < /dev/null", commandLine, outPath.string(), errPath.string());
  const int status = std::system(command.c_str());
  ProcessResult result;
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  auto slurp = [](const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  result.out = slurp(outPath);
  result.err = slurp(errPath);
  return result;
}

ProcessResult runCli(const std::string& arguments) {
  return runCommand(fmt::format("'{}' {}", cliPath().string(), arguments));
}

ProcessResult runCliWithFileSizeLimit(const std::string& arguments, long maxFileBytes) {
  // An ignored signal stays ignored across exec; prlimit (util-linux) sets the limit of the program it runs.
  return runCommand(fmt::format("trap '' XFSZ; exec prlimit --fsize={} '{}' {}", maxFileBytes, cliPath().string(),
                                arguments));
}

FileSizeLimit::FileSizeLimit(long maxFileBytes) {
  rlimit limit{};
  ::getrlimit(RLIMIT_FSIZE, &limit);
  m_previousSoftLimit = limit.rlim_cur;
  limit.rlim_cur = static_cast<rlim_t>(maxFileBytes);
  EXPECT_EQ(::setrlimit(RLIMIT_FSIZE, &limit), 0) << "cannot lower the file-size limit";
  m_previousHandler = std::signal(SIGXFSZ, SIG_IGN);
}

FileSizeLimit::~FileSizeLimit() {
  rlimit limit{};
  ::getrlimit(RLIMIT_FSIZE, &limit);
  limit.rlim_cur = static_cast<rlim_t>(m_previousSoftLimit);
  ::setrlimit(RLIMIT_FSIZE, &limit);
  std::signal(SIGXFSZ, m_previousHandler);
}

std::vector<std::string> folderEntries(const std::filesystem::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

}  // namespace fct::test
