#include "TestSupport.h"

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

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

std::filesystem::path scriptPath(const std::string& name) { return std::filesystem::path(FCT_SCRIPT_DIR) / name; }

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

}  // namespace fct::test
