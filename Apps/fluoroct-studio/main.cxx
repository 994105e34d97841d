// fluoroct-studio: the FluoroCT desktop program (thin entry point).
// fluoroct-studio [SESSION | --case DIR] [--step NAME] [--register] [--track SEQUENCE] [--screenshot FILE]
#include <QApplication>
#include <QCommandLineParser>
#include <QDir>
#include <QPixmap>
#include <QTemporaryDir>
#include <QTimer>

#include <cstdio>
#include <memory>

#include "Widgets/DataStepWidget.h"
#include "Widgets/RegisterStepWidget.h"
#include "Widgets/StudioMainWindow.h"
#include "Widgets/TrackStepWidget.h"

namespace {

/// Prints `error: message` on stderr and returns 2.
int reportError(const QString& message) {
  std::fprintf(stderr, "error: %s\n", message.toLocal8Bit().constData());
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  QApplication::setApplicationName(QStringLiteral("FluoroCT Studio"));
  QApplication::setOrganizationName(QStringLiteral("FluoroCT"));
  QApplication::setApplicationVersion(QStringLiteral("0.1.0"));

  QCommandLineParser parser;
  parser.setApplicationDescription(QStringLiteral("FluoroCT Studio: register a CT to fluoroscopic X-ray images"));
  parser.addHelpOption();
  parser.addVersionOption();
  parser.addPositionalArgument(QStringLiteral("session"), QStringLiteral("Session file to open (.fctsession.json)."),
                               QStringLiteral("[SESSION]"));
  const QCommandLineOption caseFolder(
      QStringLiteral("case"),
      QStringLiteral("Open a case folder: ct.nrrd (or ct.nii.gz, ct.mha, a DICOM folder 'ct'), views.json, and "
                     "optionally initial_pose.json and truth_pose.json."),
      QStringLiteral("dir"));
  const QCommandLineOption step(QStringLiteral("step"),
                                QStringLiteral("Show this workflow step: data, initial-pose, rois, register, review, track."),
                                QStringLiteral("name"));
  const QCommandLineOption screenshot(
      QStringLiteral("screenshot"),
      QStringLiteral("Save a PNG of the window to <file> once it is shown (and the case loaded), then quit."),
      QStringLiteral("file"));
  const QCommandLineOption runRegistration(
      QStringLiteral("register"),
      QStringLiteral("Once the case is loaded, run a registration as the Register step's Run button does (with "
                     "--screenshot: the picture is taken when it has finished)."));
  const QCommandLineOption runTracking(
      QStringLiteral("track"),
      QStringLiteral("Once the case is loaded (and registered, with --register), load the sequence of this view file "
                     "into the Track step and track it as its Track button does (with --screenshot: the picture is "
                     "taken when it has finished)."),
      QStringLiteral("sequence"));
  parser.addOption(caseFolder);
  parser.addOption(step);
  parser.addOption(runRegistration);
  parser.addOption(runTracking);
  parser.addOption(screenshot);
  parser.process(app);
  const QStringList positional = parser.positionalArguments();
  if (positional.size() > 1) return reportError(QStringLiteral("give at most one session file"));
  if (!positional.isEmpty() && parser.isSet(caseFolder)) {
    return reportError(QStringLiteral("give either a session file or --case DIR, not both"));
  }

  // A screenshot run is not a working session: its autosave goes to a throw-away folder.
  std::unique_ptr<QTemporaryDir> scratch;
  std::filesystem::path autosavePath;
  if (parser.isSet(screenshot)) {
    scratch = std::make_unique<QTemporaryDir>();
    autosavePath = std::filesystem::path(scratch->path().toStdString()) / "autosave.fctsession.json";
  }
  fct::StudioMainWindow window(autosavePath);
  if (parser.isSet(step) && !window.showStepNamed(parser.value(step))) {
    QStringList names;
    for (int i = 0; i < window.stepCount(); ++i) names << window.stepTitle(i).toLower().replace(' ', '-');
    return reportError(QStringLiteral("no step named '%1'; the steps are: %2")
                           .arg(parser.value(step), names.join(QStringLiteral(", "))));
  }
  window.show();

  // Unsaved changes of a run that crashed are offered back first, before anything else can overwrite them.
  if (!parser.isSet(screenshot)) window.offerAutosave();
  bool loading = false;
  if (!positional.isEmpty()) {
    window.openSession(positional.front());
  } else if (parser.isSet(caseFolder)) {
    loading = true;
    window.dataStep()->openCaseFolder(parser.value(caseFolder));
  }

  const auto take = [&window, &parser, &screenshot] {
    if (!parser.isSet(screenshot)) return;
    const QString path = parser.value(screenshot);
    QTimer::singleShot(700, &window, [&window, path] {
      if (!window.grab().save(path, "PNG")) {
        std::fprintf(stderr, "error: could not write the screenshot to '%s'; check the folder exists and is writable\n",
                     path.toLocal8Bit().constData());
        QApplication::exit(2);
        return;
      }
      QApplication::exit(0);  // not quit(): that would close the window and ask about the unsaved case
    });
  };
  // After registering: optionally track a sequence (the Track step shows any error in its message line), then the
  // screenshot.
  const auto afterRegistration = [&window, &parser, &runTracking, take] {
    auto* trackStep = window.findChild<fct::TrackStepWidget*>();
    if (!parser.isSet(runTracking) || trackStep == nullptr ||
        !trackStep->loadSequence(parser.value(runTracking).toStdString())) {
      take();
      return;
    }
    QObject::connect(trackStep, &fct::TrackStepWidget::runningChanged, &window, [take](bool running) {
      if (!running) take();
    });
    trackStep->startTracking();
    if (!trackStep->isRunning()) take();
  };
  // After loading: optionally register (the Register step reports any error in its own log), then the rest.
  const auto afterLoad = [&window, &parser, &runRegistration, afterRegistration] {
    auto* registerStep = window.findChild<fct::RegisterStepWidget*>();
    if (!parser.isSet(runRegistration) || registerStep == nullptr) {
      afterRegistration();
      return;
    }
    QObject::connect(registerStep, &fct::RegisterStepWidget::runningChanged, &window, [afterRegistration](bool running) {
      if (!running) afterRegistration();
    });
    if (!registerStep->run()) afterRegistration();
  };
  if (loading && window.dataStep()->isBusy()) {
    QObject::connect(window.dataStep(), &fct::DataStepWidget::loadFinished, &window, afterLoad);
  } else {
    afterLoad();
  }
  return QApplication::exec();
}
