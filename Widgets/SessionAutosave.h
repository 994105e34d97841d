#pragma once
// SessionAutosave: keeps an autosave copy of a StudioDocument in a side file, rewritten atomically (write, then
// rename) after every change while there are unsaved changes, and removed once the document is saved or emptied.
// A side file found at start-up means the last run ended with unsaved changes (a crash): the main window offers it.

#include <QObject>
#include <QString>

#include <filesystem>

#include "Base/Result.h"

namespace fct {

class StudioDocument;

/// Autosave of one document to one side file.
class SessionAutosave : public QObject {
  Q_OBJECT
 public:
  /// Watches `document`; `path` is the side file (its folder is created on first write).
  SessionAutosave(StudioDocument* document, std::filesystem::path path, QObject* parent = nullptr);

  /// The default side file: autosave.fctsession.json in the program's data folder (QStandardPaths::AppDataLocation).
  static std::filesystem::path defaultPath();
  /// The side file.
  const std::filesystem::path& path() const { return m_path; }
  /// True when the side file exists.
  bool exists() const;
  /// Writes the side file now. Fails naming the path (e.g. the folder is not writable).
  Status writeNow();
  /// Removes the side file (if any).
  void discard();
  /// Turns autosaving on or off (e.g. off while a crashed session is being offered back).
  void setEnabled(bool enabled) { m_enabled = enabled; }

 signals:
  /// An autosave failed; the message says where and why.
  void failed(const QString& message);

 private:
  StudioDocument* m_document;
  std::filesystem::path m_path;
  bool m_enabled = true;
};

}  // namespace fct
