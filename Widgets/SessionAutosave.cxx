#include "Widgets/SessionAutosave.h"

#include <QStandardPaths>

#include "Widgets/StudioDocument.h"
#include "Widgets/StudioSession.h"

namespace fct {

namespace fs = std::filesystem;

SessionAutosave::SessionAutosave(StudioDocument* document, fs::path path, QObject* parent)
    : QObject(parent), m_document(document), m_path(std::move(path)) {
  connect(document, &StudioDocument::changed, this, [this] {
    if (!m_enabled || !m_document->isModified()) return;
    const Status written = writeNow();
    if (!written) emit failed(QString::fromStdString(written.error()));
  });
  connect(document, &StudioDocument::modifiedChanged, this, [this](bool modified) {
    if (m_enabled && !modified) discard();
  });
}

fs::path SessionAutosave::defaultPath() {
  const QString folder = QStandardPaths::writableLocation(QStandardPaths::AppDataLocation);
  return fs::path(folder.toStdString()) / (std::string("autosave") + StudioSession::kSuffix);
}

bool SessionAutosave::exists() const {
  std::error_code ec;
  return fs::exists(m_path, ec);
}

Status SessionAutosave::writeNow() { return StudioSession::writeAutosave(*m_document, m_path); }

void SessionAutosave::discard() {
  std::error_code ec;
  fs::remove(m_path, ec);
}

}  // namespace fct
