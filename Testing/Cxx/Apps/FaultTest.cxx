// Faults the CLI survives: a file-size limit (as a full disk) while writing RESULT.json, a truncated Transgraph cache
// (rebuilt with a warning), kill -9 in the middle of a study (the resume loses at most the trials that were running),
// Ctrl-C during `register` (the best pose so far is written, marked cancelled) and during `track` (the frames so far
// are written, marked cancelled).
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>

#include "Base/JsonDocument.h"
#include "Evaluation/TrialStore.h"
#include "IO/Project/PoseFile.h"
#include "SimulatedCliCase.h"
#include "TestSupport.h"

namespace {

namespace fs = std::filesystem;

/// `fluoroct <arguments>` started in the background with stdout and stderr going to files in `dir`.
class BackgroundCli {
 public:
  BackgroundCli(const std::string& arguments, const fs::path& dir) : m_err(dir / "stderr.txt") {
    const std::string command = fmt::format("exec '{}' {} > '{}' 2> '{}' < /dev/null", fct::test::cliPath().string(),
                                            arguments, (dir / "stdout.txt").string(), m_err.string());
    m_pid = ::fork();
    if (m_pid == 0) {
      ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
      ::_exit(127);
    }
  }
  ~BackgroundCli() {
    if (m_pid > 0 && !m_waited) {
      ::kill(m_pid, SIGKILL);
      wait();
    }
  }
  BackgroundCli(const BackgroundCli&) = delete;
  BackgroundCli& operator=(const BackgroundCli&) = delete;

  /// Waits (at most two minutes) until `ready` holds for the program's stderr so far; false if it ended before.
  bool waitForStderr(const std::function<bool(const std::string&)>& ready) {
    for (int i = 0; i < 2400; ++i) {
      if (ready(stderrText())) return true;
      if (::waitpid(m_pid, &m_status, WNOHANG) == m_pid) {
        m_waited = true;
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }
  void signal(int number) { ::kill(m_pid, number); }
  /// Waits for the end; the wait status.
  int wait() {
    if (!m_waited) ::waitpid(m_pid, &m_status, 0);
    m_waited = true;
    return m_status;
  }
  std::string stderrText() const {
    std::ifstream in(m_err);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  }

 private:
  fs::path m_err;
  pid_t m_pid = -1;
  int m_status = 0;
  bool m_waited = false;
};

/// The number of "[k/N] ..." trial lines `evaluate` printed.
int trialLines(const std::string& err) {
  int count = 0;
  for (std::size_t at = err.find("\n["); at != std::string::npos; at = err.find("\n[", at + 1)) ++count;
  return count + (err.rfind("[", 0) == 0 ? 1 : 0);
}

}  // namespace

TEST(RegisterFault, FileSizeLimitKeepsThePreviousResultJsonAndSaysWhy) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = fct::test::makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(fct::test::perturbed(truth), dir / "init.json").ok());
  const std::string arguments =
      fmt::format("register --ct '{}' --views '{}' --init '{}' --preset fast --out '{}'", (dir / "ct.nrrd").string(),
                  (dir / "sim" / "views.json").string(), (dir / "init.json").string(), (dir / "RESULT.json").string());
  ASSERT_EQ(fct::test::runCli(arguments).exitCode, 0);
  const std::string previous = fct::test::readText(dir / "RESULT.json");

  const auto limited = fct::test::runCliWithFileSizeLimit(arguments + " --seed 9", 512);
  EXPECT_TRUE(fct::test::oneErrorLine(limited)) << limited.exitCode << ": " << limited.err;
  EXPECT_NE(limited.err.find("RESULT.json"), std::string::npos) << limited.err;
  EXPECT_NE(limited.err.find("File too large"), std::string::npos) << limited.err;
  EXPECT_EQ(fct::test::readText(dir / "RESULT.json"), previous);
  for (const auto& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

TEST(EvaluateFault, KillDashNineMidStudyLosesAtMostTheTrialsThatWereRunning) {
  const fs::path dir = fct::test::scratchDir();
  const fs::path out = dir / "study";
  const std::string arguments = fmt::format("evaluate --study table2 --quick --out '{}'", out.string());
  int printed = 0;
  {
    BackgroundCli study(arguments, dir);
    ASSERT_TRUE(study.waitForStderr([](const std::string& err) { return trialLines(err) >= 2; }))
        << "the study ended or stalled before its second trial: " << study.stderrText();
    study.signal(SIGKILL);
    const int status = study.wait();
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "the study ended before the kill";
    printed = trialLines(study.stderrText());
  }
  // The CSV is whole (never half-written) and holds every trial reported finished; only the running one is missing.
  auto killed = fct::TrialStore::open(out / "trials.csv");
  ASSERT_TRUE(killed.ok()) << killed.error();
  const std::vector<fct::TrialRecord> kept = killed.value().records();
  ASSERT_GE(static_cast<int>(kept.size()), printed);
  ASSERT_LT(kept.size(), 6u);

  const auto resumed = fct::test::runCli(arguments);
  ASSERT_EQ(resumed.exitCode, 0) << resumed.err;
  EXPECT_NE(resumed.out.find(fmt::format("ran {} trials (0 failed), skipped {}", 6 - kept.size(), kept.size())),
            std::string::npos)
      << resumed.out;
  const auto all = fct::TrialStore::open(out / "trials.csv");
  ASSERT_TRUE(all.ok()) << all.error();
  ASSERT_EQ(all.value().records().size(), 6u);
  for (std::size_t i = 0; i < kept.size(); ++i) {  // the trials done before the kill are kept as they were
    EXPECT_EQ(all.value().records()[i].condition, kept[i].condition);
    EXPECT_EQ(all.value().records()[i].trial, kept[i].trial);
    EXPECT_EQ(all.value().records()[i].error.streMean_mm, kept[i].error.streMean_mm);
  }
}

TEST(RegisterFault, CtrlCWritesTheBestPoseSoFarMarkedCancelled) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = fct::test::makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(fct::test::perturbed(truth), dir / "init.json").ok());
  BackgroundCli registration(
      fmt::format("register --ct '{}' --views '{}' --init '{}' --preset paper --progress --out '{}'",
                  (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(), (dir / "init.json").string(),
                  (dir / "RESULT.json").string()),
      dir);
  ASSERT_TRUE(registration.waitForStderr([](const std::string& err) { return err.find("stage 1/") != std::string::npos; }))
      << "the registration ended before its progress bar showed: " << registration.stderrText();
  registration.signal(SIGINT);
  const int status = registration.wait();
  ASSERT_TRUE(WIFEXITED(status)) << "Ctrl-C ended the process instead of cancelling the registration";
  EXPECT_EQ(WEXITSTATUS(status), 0) << registration.stderrText();
  EXPECT_NE(fct::test::readText(dir / "stdout.txt").find("cancelled in"), std::string::npos);

  auto result = fct::JsonDocument::parse(dir / "RESULT.json");
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value().at("cancelled"), true);
  auto pose = fct::PoseFile::read(dir / "RESULT.json");
  ASSERT_TRUE(pose.ok()) << pose.error();
  EXPECT_TRUE(pose.value().matrix().allFinite());
}

TEST(TrackFault, CtrlCWritesTheFramesSoFarMarkedCancelled) {
  const fs::path dir = fct::test::scratchDir();
  const std::vector<Eigen::Isometry3d> truth = fct::test::makeTrackCase(dir, 16);
  ASSERT_TRUE(fct::PoseFile::write(fct::test::perturbed(truth[0]), dir / "init.json").ok());
  BackgroundCli tracking(fmt::format("track --ct '{}' --views '{}' --init '{}' --preset fast --level 0 --out '{}'",
                                     (dir / "ct.nrrd").string(), (dir / "track_views.json").string(),
                                     (dir / "init.json").string(), (dir / "out").string()),
                         dir);
  ASSERT_TRUE(tracking.waitForStderr([](const std::string& err) { return err.find("frame    2/") != std::string::npos; }))
      << "the tracking ended before frame 2: " << tracking.stderrText();
  tracking.signal(SIGINT);
  const int status = tracking.wait();
  ASSERT_TRUE(WIFEXITED(status)) << "Ctrl-C ended the process instead of stopping the tracking";
  EXPECT_EQ(WEXITSTATUS(status), 0) << tracking.stderrText();
  EXPECT_NE(fct::test::readText(dir / "stdout.txt").find("cancelled after"), std::string::npos);
  auto result = fct::JsonDocument::parse(dir / "out" / "track.json");
  ASSERT_TRUE(result.ok()) << result.error();
  EXPECT_EQ(result.value().at("cancelled"), true);
  const std::size_t done = result.value().at("frames").size();
  EXPECT_GE(done, 3u);
  EXPECT_LT(done, 16u);
  EXPECT_TRUE(fs::exists(dir / "out" / "track.csv"));
}

TEST(RegisterFault, TruncatedTransgraphCacheIsRebuiltWithAWarning) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = fct::test::makeCase(dir);
  ASSERT_TRUE(fct::PoseFile::write(fct::test::perturbed(truth), dir / "init.json").ok());
  const fs::path cache = dir / "cache";
  const std::string arguments = fmt::format(
      "register --ct '{}' --views '{}' --init '{}' --preset fast --method transgraph --transgraph-spacing-mm 12 "
      "--transgraph-cache '{}' --out '{}'",
      (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(), (dir / "init.json").string(), cache.string(),
      (dir / "RESULT.json").string());
  ASSERT_EQ(fct::test::runCli(arguments).exitCode, 0);
  const fs::path table = fs::directory_iterator(cache)->path();
  const auto size = fs::file_size(table);
  fs::resize_file(table, size / 3);  // as after a crash of a writer that did not write atomically

  const auto run = fct::test::runCli(arguments);
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_NE(run.err.find("is unusable"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("rebuilt it"), std::string::npos) << run.err;
  EXPECT_EQ(fs::file_size(table), size) << "the rebuilt table was written back";
}
