// fluoroct-studio: the FluoroCT desktop program (thin entry point).
#include <QApplication>

#include "MainWindow.h"

int main(int argc, char** argv) {
  QApplication app(argc, argv);
  QApplication::setApplicationName(QStringLiteral("FluoroCT Studio"));
  QApplication::setOrganizationName(QStringLiteral("FluoroCT"));
  fct::MainWindow window;
  window.show();
  return QApplication::exec();
}
