#include "IO/Dicom/DicomValues.h"

#include <dcmtk/dcmdata/dcelem.h>
#include <dcmtk/dcmdata/dcitem.h>

#include <cmath>
#include <cstdlib>

namespace fct {

namespace {

std::string trimmed(const OFString& value) {
  const std::string s(value.c_str());
  static const std::string kBlanks(" \t\r\n\0", 5);
  const auto first = s.find_first_not_of(kBlanks);
  if (first == std::string::npos) return {};
  return s.substr(first, s.find_last_not_of(kBlanks) - first + 1);
}

}  // namespace

std::string DicomValues::text(DcmItem& item, const DcmTagKey& tag) {
  OFString value;
  if (item.findAndGetOFStringArray(tag, value).bad()) return {};
  return trimmed(value);
}

std::string DicomValues::text(DcmItem& item, const DcmTagKey& tag, unsigned long pos) {
  OFString value;
  if (item.findAndGetOFString(tag, value, pos).bad()) return {};
  return trimmed(value);
}

std::optional<double> DicomValues::number(DcmItem& item, const DcmTagKey& tag, unsigned long pos, bool searchIntoSub) {
  Float64 value = 0.0;
  if (item.findAndGetFloat64(tag, value, pos, searchIntoSub).good() && std::isfinite(value)) return value;
  OFString text;  // IS and DS are strings; some DCMTK paths only expose them as text
  if (item.findAndGetOFString(tag, text, pos, searchIntoSub).good()) {
    const std::string s = trimmed(text);
    if (s.empty()) return std::nullopt;
    char* end = nullptr;
    const double parsed = std::strtod(s.c_str(), &end);
    if (end != s.c_str() && std::isfinite(parsed)) return parsed;
  }
  return std::nullopt;
}

unsigned long DicomValues::count(DcmItem& item, const DcmTagKey& tag, bool searchIntoSub) {
  DcmElement* element = nullptr;
  if (item.findAndGetElement(tag, element, searchIntoSub).bad() || !element || element->getLength() == 0) return 0;
  return element->getVM();
}

}  // namespace fct
