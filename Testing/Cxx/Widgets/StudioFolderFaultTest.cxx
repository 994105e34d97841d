// Disk faults while the Studio has a case open: the case folder (CT and X-rays) disappears or changes, or the disk fills
// while it saves the session. The Studio keeps working on what it loaded; whatever reads the folder again (reopening
// the case or a session) shows a message naming the missing or damaged file, and a failed save says why and keeps the
// previous session file.
#include <gtest/gtest.h>

#include <QStandardPaths>
#include <QTest>

#include <filesystem>
#include <fstream>

#include "DialogAnswerer.h"
#include "EventLoopExceptions.h"
#include "StepTestSession.h"
#include "StudioTestCase.h"
#include "TestSupport.h"
#include "Widgets/DataStepWidget.h"
#include "Widgets/RegisterStepWidget.h"
#include "Widgets/StudioDocument.h"
#include "Widgets/StudioMainWindow.h"
#include "Widgets/XrayViewWidget.h"

namespace {

namespace fs = std::filesystem;

QString qs(const fs::path& path) { return QString::fromStdString(path.string()); }

class StudioFolderFault : public ::testing::Test {
 protected:
  void SetUp() override {
    QStandardPaths::setTestModeEnabled(true);
    ASSERT_FALSE(fct::test::builtinCaseDir().empty());
    m_dir = fct::test::scratchDir();
    m_case = m_dir / "case";
    fs::copy(fct::test::builtinCaseDir(), m_case, fs::copy_options::recursive);
    m_window = std::make_unique<fct::StudioMainWindow>(m_dir / "autosave.fctsession.json");
    m_window->show();
    ASSERT_TRUE(QTest::qWaitForWindowExposed(m_window.get()));
    ASSERT_TRUE(load(m_case));
    ASSERT_TRUE(m_window->saveSessionTo(qs(m_dir / "session.fctsession.json")));
  }
  void TearDown() override {
    m_window.reset();
    EXPECT_EQ(fct::test::eventLoopExceptionCount(), 0);
  }

  /// Opens a case folder through the Data step and waits; true when it loaded.
  bool load(const fs::path& folder) {
    fct::DataStepWidget* data = m_window->dataStep();
    bool ok = false;
    const auto connection = QObject::connect(data, &fct::DataStepWidget::loadFinished,
                                             [&ok](bool success, const QString&) { ok = success; });
    data->openCaseFolder(qs(folder));
    EXPECT_TRUE(fct::test::waitUntil([&] { return !data->isBusy(); }, 60000));
    QObject::disconnect(connection);
    return ok;
  }

  /// Goes through every step, clicks each X-ray view and runs a fast registration to its end on the loaded data.
  void keepWorking() {
    for (int i = 0; i < m_window->stepCount(); ++i) m_window->showStep(i);
    for (fct::XrayViewWidget* view : m_window->xrayViews()) {
      QTest::mouseClick(view, Qt::LeftButton, Qt::NoModifier, view->rect().center());
    }
    auto* registration = m_window->findChild<fct::RegisterStepWidget*>();
    ASSERT_TRUE(registration->run()) << registration->message().toStdString();
    ASSERT_TRUE(fct::test::waitUntil([&] { return !registration->isRunning(); }, 120000));
    ASSERT_NE(m_window->document()->result(), nullptr) << registration->message().toStdString();
    EXPECT_FALSE(m_window->document()->result()->cancelled);
  }

  const fct::test::DialogAnswerer m_answerer;  // "discard the unsaved changes?" before each reload
  fs::path m_dir, m_case;
  std::unique_ptr<fct::StudioMainWindow> m_window;
};

}  // namespace

TEST_F(StudioFolderFault, AVanishedCaseFolderKeepsTheLoadedCaseAndReopeningSaysWhatIsMissing) {
  fs::remove_all(m_case);
  keepWorking();
  EXPECT_TRUE(m_window->saveSessionTo(qs(m_dir / "after.fctsession.json")));

  EXPECT_FALSE(m_window->openSession(qs(m_dir / "session.fctsession.json")));
  EXPECT_TRUE(m_window->lastMessage().contains(QStringLiteral("ct.nrrd"))) << m_window->lastMessage().toStdString();
  EXPECT_NE(m_window->document()->ct(), nullptr) << "the open session stays";
  EXPECT_FALSE(load(m_case));
  EXPECT_TRUE(m_window->lastMessage().contains(QStringLiteral("case"))) << m_window->lastMessage().toStdString();
  EXPECT_NE(m_window->document()->ct(), nullptr);
}

TEST_F(StudioFolderFault, ChangedFilesInTheOpenCaseFolderGiveAMessageWhenRead) {
  // Another program overwrites the CT with half of it and removes one X-ray.
  const std::string ct = fct::test::readText(m_case / "ct.nrrd");
  std::ofstream(m_case / "ct.nrrd", std::ios::binary | std::ios::trunc) << ct.substr(0, ct.size() / 2);
  fs::remove(m_case / "lateral.png");
  keepWorking();

  EXPECT_FALSE(load(m_case));
  EXPECT_TRUE(m_window->lastMessage().contains(QStringLiteral("ct.nrrd"))) << m_window->lastMessage().toStdString();
  EXPECT_FALSE(m_window->openSession(qs(m_dir / "session.fctsession.json")));
  EXPECT_FALSE(m_window->lastMessage().isEmpty());
  EXPECT_NE(m_window->document()->ct(), nullptr) << "the loaded case stays";

  // The CT back but still without the lateral X-ray: the message names the missing image.
  std::ofstream(m_case / "ct.nrrd", std::ios::binary | std::ios::trunc) << ct;
  EXPECT_FALSE(load(m_case));
  EXPECT_TRUE(m_window->lastMessage().contains(QStringLiteral("lateral.png"))) << m_window->lastMessage().toStdString();
}

TEST_F(StudioFolderFault, AFullDiskWhileSavingTheSessionKeepsThePreviousFileAndSaysWhy) {
  const fs::path session = m_dir / "session.fctsession.json";
  const std::string before = fct::test::readText(session);
  keepWorking();  // the session now has a result to save
  {
    const fct::test::FileSizeLimit full(64);  // every write past 64 bytes fails with EFBIG, as on a full disk
    EXPECT_FALSE(m_window->saveSessionTo(qs(session)));
  }
  EXPECT_TRUE(m_window->lastMessage().contains(QStringLiteral("File too large"))) << m_window->lastMessage().toStdString();
  EXPECT_TRUE(m_window->lastMessage().contains(QStringLiteral("session.fctsession.json")));
  EXPECT_EQ(fct::test::readText(session), before) << "the previous session file is unchanged";
  for (const std::string& entry : fct::test::folderEntries(m_dir)) {
    EXPECT_NE(entry.rfind(".session", 0), 0u) << "a temporary file is left: " << entry;
  }
  EXPECT_TRUE(m_window->document()->isModified()) << "the unsaved work is still marked unsaved";

  ASSERT_TRUE(m_window->saveSessionTo(qs(session))) << m_window->lastMessage().toStdString();
  EXPECT_NE(fct::test::readText(session), before);
  EXPECT_FALSE(m_window->document()->isModified());
}
