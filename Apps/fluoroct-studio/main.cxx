// fluoroct-studio: the FluoroCT desktop program (thin entry point).
#include <QApplication>
#include <QCommandLineParser>
#include <QPixmap>
#include <QTimer>

#include <cstdio>

#include "MainWindow.h"

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  QApplication::setApplicationName(QStringLiteral("FluoroCT Studio"));
  QApplication::setOrganizationName(QStringLiteral("FluoroCT"));
  QApplication::setApplicationVersion(QStringLiteral("0.1.0"));

  QCommandLineParser parser;
  parser.setApplicationDescription(QStringLiteral("FluoroCT Studio: register a CT to fluoroscopic X-ray images"));
  parser.addHelpOption();
  parser.addVersionOption();
  const QCommandLineOption screenshot(QStringLiteral("screenshot"),
                                      QStringLiteral("Save a PNG of the window to <file> once it is shown, then quit."),
                                      QStringLiteral("file"));
  parser.addOption(screenshot);
  parser.process(app);

  fct::MainWindow window;
  window.show();
  if (parser.isSet(screenshot)) {
    const QString path = parser.value(screenshot);
    QTimer::singleShot(500, &window, [&window, path] {
      if (!window.grab().save(path, "PNG")) {
        std::fprintf(stderr, "error: could not write the screenshot to '%s'; check the folder exists and is writable\n",
                     path.toLocal8Bit().constData());
        QApplication::exit(2);
        return;
      }
      QApplication::quit();
    });
  }
  return QApplication::exec();
}
