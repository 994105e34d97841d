#pragma once
// DeflatedDatasetCheck: refuses a deflated DICOM file whose elements declare more bytes than the file inflates to,
// before DCMTK parses it (DCMTK allocates a declared length up front when it reads a compressed stream).

#include <filesystem>

#include "Base/Result.h"

namespace fct {

/// A look at the element lengths of a Part 10 file in the Deflated Explicit VR Little Endian transfer syntax.
class DeflatedDatasetCheck {
 public:
  /// Ok for a file in any other transfer syntax, or a deflated one whose every element, item and fragment fits in
  /// the bytes its dataset inflates to; an error naming the first element that does not (or the damaged stream).
  /// Every DICOM reader of this folder calls it before DCMTK loads the file.
  static Status check(const std::filesystem::path& path);
};

}  // namespace fct
