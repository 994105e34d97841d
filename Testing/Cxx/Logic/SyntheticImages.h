#pragma once
// Small synthetic images shared by the Logic tests (header-only).

#include <cmath>

#include "Image/FloatImage.h"

namespace fct::test {

/// A bone-like test image: a bright disc (radius 20) and a bright bar with soft texture on a gentle ramp.
inline FloatImage phantomImage(int cols = 128, int rows = 112) {
  FloatImage image = FloatImage::filled(cols, rows);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      float v = 0.01f * c + 0.3f * std::sin(0.21f * c) * std::cos(0.17f * r);
      if (std::hypot(c - 0.35 * cols, r - 0.45 * rows) < 20.0) v += 2.0f;
      if (c > 0.6 * cols && c < 0.75 * cols && r > 10 && r < rows - 10) v += 1.5f;
      image.at(c, r) = v;
    }
  }
  return image;
}

/// The same image with every pixel mapped to gain * v + offset.
inline FloatImage affine(const FloatImage& image, float gain, float offset) {
  FloatImage out = image;
  for (float& v : out.pixels) v = gain * v + offset;
  return out;
}

}  // namespace fct::test
