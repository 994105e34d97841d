#include "IO/Dicom/DicomCodecs.h"

#include <dcmtk/dcmdata/dcrledrg.h>
#include <dcmtk/dcmjpeg/djdecode.h>
#include <dcmtk/dcmjpls/djdecode.h>
#include <dcmtk/oflog/oflog.h>

#include <mutex>

namespace fct {

void DicomCodecs::ensureRegistered() {
  static std::once_flag once;
  std::call_once(once, [] {
    // DCMTK reports problems both through OFCondition (which the readers convert into Result errors) and through
    // its logger (stderr noise that would break the CLI's one-line error rule): keep only fatal messages.
    OFLog::getLogger("dcmtk").setLogLevel(OFLogger::FATAL_LOG_LEVEL);
    DJDecoderRegistration::registerCodecs();
    DJLSDecoderRegistration::registerCodecs();
    DcmRLEDecoderRegistration::registerCodecs();
  });
}

}  // namespace fct
