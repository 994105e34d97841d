#pragma once
// MainWindow: the FluoroCT Studio main window (module panel on the left, views on the right, status line).

#include <QMainWindow>

namespace fct {

/// The desktop program's top-level window.
class MainWindow : public QMainWindow {
  Q_OBJECT
 public:
  /// Builds the window with its menus and an empty workspace.
  explicit MainWindow(QWidget* parent = nullptr);
};

}  // namespace fct
