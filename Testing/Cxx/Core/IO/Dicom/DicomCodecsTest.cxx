#include <dcmtk/dcmdata/dccodec.h>
#include <dcmtk/dcmdata/dcxfer.h>
#include <gtest/gtest.h>

#include "IO/Dicom/DicomCodecs.h"

TEST(DicomCodecs, RegistersJpegJpegLsAndRleDecoders) {
  fct::DicomCodecs::ensureRegistered();
  fct::DicomCodecs::ensureRegistered();  // idempotent
  DcmXfer jpegBaseline(EXS_JPEGProcess1);
  DcmXfer jpegLs(EXS_JPEGLSLossless);
  DcmXfer rle(EXS_RLELossless);
  EXPECT_TRUE(jpegBaseline.isEncapsulated());
  // A decoder is registered for each when DcmCodecList can handle the conversion to uncompressed.
  EXPECT_TRUE(DcmCodecList::canChangeCoding(EXS_JPEGProcess1, EXS_LittleEndianExplicit));
  EXPECT_TRUE(DcmCodecList::canChangeCoding(EXS_JPEGLSLossless, EXS_LittleEndianExplicit));
  EXPECT_TRUE(DcmCodecList::canChangeCoding(EXS_RLELossless, EXS_LittleEndianExplicit));
}
