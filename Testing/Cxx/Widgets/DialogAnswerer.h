#pragma once
// Answers the Studio's questions in tests that drive it like a user without knowing when it will ask.

#include <QAbstractButton>
#include <QApplication>
#include <QDialog>
#include <QMessageBox>
#include <QTimer>

namespace fct::test {

/// Answers every modal dialog that opens: a message box with Discard, No or Cancel (in that order of preference),
/// any other dialog (a file dialog) is rejected.
class DialogAnswerer {
 public:
  DialogAnswerer() {
    m_timer.setInterval(5);
    QObject::connect(&m_timer, &QTimer::timeout, [this] { answer(); });
    m_timer.start();
  }
  int answered() const { return m_answered; }

 private:
  void answer() {
    auto* dialog = qobject_cast<QDialog*>(QApplication::activeModalWidget());
    if (!dialog) return;
    ++m_answered;
    if (auto* box = qobject_cast<QMessageBox*>(dialog)) {
      for (QMessageBox::StandardButton choice : {QMessageBox::Discard, QMessageBox::No, QMessageBox::Cancel,
                                                 QMessageBox::Ok}) {
        if (QAbstractButton* button = box->button(choice)) {
          button->click();
          return;
        }
      }
    }
    dialog->reject();
  }
  QTimer m_timer;
  int m_answered = 0;
};

}  // namespace fct::test
