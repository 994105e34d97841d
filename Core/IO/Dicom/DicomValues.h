#pragma once
// DicomValues: trimmed text and finite numbers from DICOM attributes, for the readers of this folder (DCMTK stays
// inside IO/Dicom).

#include <optional>
#include <string>

class DcmItem;
class DcmTagKey;

namespace fct {

/// Attribute values as the readers need them: absent, empty and unparsable values all come back as "none".
class DicomValues {
 public:
  /// All values of `tag` joined by '\', without surrounding blanks; empty when absent.
  static std::string text(DcmItem& item, const DcmTagKey& tag);
  /// Value `pos` of `tag`, without surrounding blanks; empty when absent.
  static std::string text(DcmItem& item, const DcmTagKey& tag, unsigned long pos);
  /// Value `pos` of a numeric attribute (DS, IS, FD, FL, US, ...) as a finite number; nullopt when absent, empty or
  /// not finite. `searchIntoSub` also looks inside the item's sequences (a functional-group item's macros).
  static std::optional<double> number(DcmItem& item, const DcmTagKey& tag, unsigned long pos = 0,
                                      bool searchIntoSub = false);
  /// Number of values of `tag` (0 when absent or empty).
  static unsigned long count(DcmItem& item, const DcmTagKey& tag, bool searchIntoSub = false);
};

}  // namespace fct
