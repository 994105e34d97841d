#pragma once
// DicomCodecs: sets DCMTK up once per process: decoders for compressed transfer syntaxes, quiet logging.

namespace fct {

/// Registers DCMTK's JPEG (baseline, extended, lossless), JPEG-LS and RLE decoders and lowers DCMTK's own logging
/// to fatal messages (problems reach the user through Result errors instead). Idempotent and thread-safe; every
/// DICOM reader calls it first.
class DicomCodecs {
 public:
  static void ensureRegistered();
};

}  // namespace fct
