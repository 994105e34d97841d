#include "Image/ValidMask.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace fct {

ValidMask ValidMask::allValid(int cols, int rows) {
  return ValidMask{cols, rows, std::vector<std::uint8_t>(static_cast<std::size_t>(cols) * rows, 1)};
}

Result<ValidMask> ValidMask::fromBytes(int cols, int rows, const std::vector<std::uint8_t>& bytes) {
  if (cols <= 0 || rows <= 0 || bytes.size() != static_cast<std::size_t>(cols) * rows) {
    return fail(fmt::format("mask has {} bytes but the image is {}x{} pixels; give one byte per pixel", bytes.size(),
                            cols, rows));
  }
  ValidMask mask{cols, rows, std::vector<std::uint8_t>(bytes.size())};
  std::transform(bytes.begin(), bytes.end(), mask.valid.begin(), [](std::uint8_t b) { return b ? 1 : 0; });
  return mask;
}

void ValidMask::excludeMargin(int margin_px) {
  if (margin_px <= 0) return;
  for (int row = 0; row < rows; ++row) {
    const bool rowInMargin = row < margin_px || row >= rows - margin_px;
    std::uint8_t* line = valid.data() + static_cast<std::size_t>(row) * cols;
    if (rowInMargin) {
      std::fill(line, line + cols, std::uint8_t{0});
    } else {
      std::fill(line, line + std::min(margin_px, cols), std::uint8_t{0});
      std::fill(line + std::max(0, cols - margin_px), line + cols, std::uint8_t{0});
    }
  }
}

void ValidMask::excludeOutside(const PixelCircle& circle) {
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      if (!circle.contains(col, row)) valid[static_cast<std::size_t>(row) * cols + col] = 0;
    }
  }
}

void ValidMask::excludeInside(const PixelCircle& circle) {
  const int row0 = std::max(0, static_cast<int>(std::floor(circle.centre_px.y() - circle.radius_px)));
  const int row1 = std::min(rows - 1, static_cast<int>(std::ceil(circle.centre_px.y() + circle.radius_px)));
  const int col0 = std::max(0, static_cast<int>(std::floor(circle.centre_px.x() - circle.radius_px)));
  const int col1 = std::min(cols - 1, static_cast<int>(std::ceil(circle.centre_px.x() + circle.radius_px)));
  for (int row = row0; row <= row1; ++row) {
    for (int col = col0; col <= col1; ++col) {
      if (circle.contains(col, row)) valid[static_cast<std::size_t>(row) * cols + col] = 0;
    }
  }
}

Status ValidMask::intersect(const ValidMask& other) {
  if (other.cols != cols || other.rows != rows) {
    return fail(fmt::format("cannot combine a {}x{} mask with a {}x{} mask; both must match the image size", cols, rows,
                            other.cols, other.rows));
  }
  for (std::size_t i = 0; i < valid.size(); ++i) valid[i] = static_cast<std::uint8_t>(valid[i] & other.valid[i]);
  return Ok{};
}

Result<double> ValidMask::excludedFractionWithin(const ValidMask& kept, const ValidMask& region) const {
  for (const ValidMask* other : {&kept, &region}) {
    if (other->cols != cols || other->rows != rows) {
      return fail(fmt::format("cannot count a {}x{} mask's pixels in a {}x{} mask; both must match the image size",
                              other->cols, other->rows, cols, rows));
    }
  }
  std::size_t inRegion = 0, excluded = 0;
  for (std::size_t i = 0; i < valid.size(); ++i) {
    if (valid[i] == 0 || region.valid[i] == 0) continue;
    ++inRegion;
    if (kept.valid[i] == 0) ++excluded;
  }
  return inRegion == 0 ? 0.0 : static_cast<double>(excluded) / static_cast<double>(inRegion);
}

std::size_t ValidMask::validCount() const {
  return static_cast<std::size_t>(std::count_if(valid.begin(), valid.end(), [](std::uint8_t v) { return v != 0; }));
}

PixelIndexList ValidMask::pixelList() const {
  PixelIndexList list;
  list.reserve(validCount());
  for (std::size_t i = 0; i < valid.size(); ++i) {
    if (valid[i]) list.push_back(static_cast<std::int32_t>(i));
  }
  return list;
}

}  // namespace fct
