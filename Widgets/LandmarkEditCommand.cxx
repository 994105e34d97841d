#include "Widgets/LandmarkEditCommand.h"

#include <utility>

#include "Widgets/StudioDocument.h"

namespace fct {

LandmarkEditCommand::LandmarkEditCommand(StudioDocument* document, Landmarks before, Landmarks after,
                                         const QString& text, QString dragKey)
    : QUndoCommand(text),
      m_document(document),
      m_before(std::move(before)),
      m_after(std::move(after)),
      m_dragKey(std::move(dragKey)) {}

void LandmarkEditCommand::redo() { m_document->setLandmarks(m_after); }

void LandmarkEditCommand::undo() { m_document->setLandmarks(m_before); }

bool LandmarkEditCommand::mergeWith(const QUndoCommand* other) {
  const auto* edit = dynamic_cast<const LandmarkEditCommand*>(other);
  if (!edit || edit->m_dragKey.isEmpty() || edit->m_dragKey != m_dragKey) return false;
  m_after = edit->m_after;
  return true;
}

}  // namespace fct
