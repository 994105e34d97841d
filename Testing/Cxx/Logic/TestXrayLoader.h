#pragma once
// Test-only loader of a single-frame greyscale DICOM X-ray through DCMTK, for Logic tests that need a real image
// before the product's X-ray reader exists on this branch. Not a product reader: no geometry, first frame only.

#include <filesystem>
#include <optional>

#include "Image/XrayImage.h"

namespace fct::test {

/// The first frame of a monochrome DICOM file as float pixels (stored values, MONOCHROME1 inverted); nullopt on error.
std::optional<XrayImage> loadXrayWithDcmtk(const std::filesystem::path& path);

}  // namespace fct::test
