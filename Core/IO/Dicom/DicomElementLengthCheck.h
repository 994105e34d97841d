#pragma once
// DicomElementLengthCheck: refuses a DICOM file whose elements declare more bytes than the file holds, before DCMTK
// parses it (DCMTK allocates some declared lengths up front, e.g. every one in a deflated stream).

#include <filesystem>

#include "Base/Result.h"

namespace fct {

/// A look at the element lengths of a DICOM file (Part 10 or a bare dataset), in the transfer syntax DCMTK reads it in.
class DicomElementLengthCheck {
 public:
  /// Ok for a file that is not DICOM, or whose every element, item and fragment fits in the bytes that follow it
  /// (in a deflated file: the bytes its dataset inflates to); an error naming the first element that does not (or
  /// the damaged deflate stream). Every DICOM reader of this folder calls it before DCMTK loads the file.
  static Status check(const std::filesystem::path& path);
};

}  // namespace fct
