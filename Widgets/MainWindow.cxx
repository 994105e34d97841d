#include "MainWindow.h"

#include <QLabel>
#include <QMenuBar>
#include <QStatusBar>

namespace fct {

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent) {
  setWindowTitle(QStringLiteral("FluoroCT Studio"));
  resize(1280, 800);
  auto* fileMenu = menuBar()->addMenu(QStringLiteral("&File"));
  fileMenu->addAction(QStringLiteral("&Quit"), QKeySequence::Quit, this, &QWidget::close);
  auto* placeholder = new QLabel(QStringLiteral("FluoroCT Studio: CT to fluoroscopy registration"), this);
  placeholder->setAlignment(Qt::AlignCenter);
  setCentralWidget(placeholder);
  statusBar()->showMessage(QStringLiteral("Ready"));
}

}  // namespace fct
