#pragma once
// LandmarkEditCommand: one undoable edit of the document's landmarks (add, move, rename, delete, load) for the
// Initial pose step's QUndoStack: it holds the landmarks before and after and sets one or the other in the document.
// Consecutive drags of the same point merge into one command, so one undo puts the point back where the drag began.

#include <QString>
#include <QUndoCommand>

#include "Geometry/Landmarks.h"

namespace fct {

class StudioDocument;

/// An undoable replacement of the document's landmarks.
class LandmarkEditCommand : public QUndoCommand {
 public:
  /// Command id of point drags (merged while the same point is dragged).
  static constexpr int kDragId = 1;

  /// An edit named `text` ("Move L2 in ap") from `before` to `after`; `dragKey` (not empty) marks a drag of one point,
  /// merged with the next drag of the same key.
  LandmarkEditCommand(StudioDocument* document, Landmarks before, Landmarks after, const QString& text,
                      QString dragKey = {});

  /// Sets the landmarks after the edit.
  void redo() override;
  /// Sets the landmarks before the edit.
  void undo() override;
  /// kDragId for drags, else -1 (never merged).
  int id() const override { return m_dragKey.isEmpty() ? -1 : kDragId; }
  /// Takes over the end of a following drag of the same point; false otherwise.
  bool mergeWith(const QUndoCommand* other) override;

 private:
  StudioDocument* m_document;
  Landmarks m_before;
  Landmarks m_after;
  QString m_dragKey;
};

}  // namespace fct
