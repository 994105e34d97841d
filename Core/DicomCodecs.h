#pragma once
// DicomCodecs: registers DCMTK's decoders for compressed transfer syntaxes once per process.

namespace fct {

/// Registers DCMTK's JPEG (baseline, extended, lossless), JPEG-LS and RLE decoders. Idempotent and thread-safe;
/// every reader of DICOM pixel data calls it first.
class DicomCodecs {
 public:
  static void ensureRegistered();
};

}  // namespace fct
