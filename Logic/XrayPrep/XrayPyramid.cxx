#include "XrayPrep/XrayPyramid.h"

#include <fmt/format.h>

namespace fct {

FloatImage XrayPyramid::downsampleByTwo(const FloatImage& image) {
  FloatImage out = FloatImage::filled(image.cols / 2, image.rows / 2);
  for (int row = 0; row < out.rows; ++row) {
    const float* top = image.pixels.data() + static_cast<std::size_t>(2 * row) * image.cols;
    const float* bottom = top + image.cols;
    float* dst = out.pixels.data() + static_cast<std::size_t>(row) * out.cols;
    for (int col = 0; col < out.cols; ++col) {
      dst[col] = 0.25f * (top[2 * col] + top[2 * col + 1] + bottom[2 * col] + bottom[2 * col + 1]);
    }
  }
  return out;
}

ValidMask XrayPyramid::downsampleByTwo(const ValidMask& mask) {
  ValidMask out = ValidMask::allValid(mask.cols / 2, mask.rows / 2);
  for (int row = 0; row < out.rows; ++row) {
    const std::uint8_t* top = mask.valid.data() + static_cast<std::size_t>(2 * row) * mask.cols;
    const std::uint8_t* bottom = top + mask.cols;
    std::uint8_t* dst = out.valid.data() + static_cast<std::size_t>(row) * out.cols;
    for (int col = 0; col < out.cols; ++col) {
      dst[col] = static_cast<std::uint8_t>(top[2 * col] && top[2 * col + 1] && bottom[2 * col] && bottom[2 * col + 1]);
    }
  }
  return out;
}

Result<XrayPyramid> XrayPyramid::build(const FloatImage& image, const ValidMask& mask,
                                       const std::optional<Camera>& camera, int levelCount) {
  if (levelCount < 1 || levelCount > 8) {
    return fail(fmt::format("pyramid level count {} out of range; use 1 to 8 (3 = levels 1, 1:4, 1:16)", levelCount));
  }
  if (image.cols <= 0 || image.rows <= 0 || image.pixels.size() != static_cast<std::size_t>(image.cols) * image.rows) {
    return fail(fmt::format("cannot build a pyramid of a {}x{} image with {} pixels", image.cols, image.rows,
                            image.pixels.size()));
  }
  if (mask.cols != image.cols || mask.rows != image.rows || mask.valid.size() != image.pixels.size()) {
    return fail(fmt::format("mask is {}x{} but the X-ray is {}x{}; build the mask for this image", mask.cols,
                            mask.rows, image.cols, image.rows));
  }
  if (camera && (camera->intrinsics().cols != image.cols || camera->intrinsics().rows != image.rows)) {
    return fail(fmt::format("camera detector is {}x{} pixels but the X-ray is {}x{}; the view's geometry does not "
                            "belong to this image",
                            camera->intrinsics().cols, camera->intrinsics().rows, image.cols, image.rows));
  }
  const int top = levelCount - 1;
  if ((image.cols >> top) < 1 || (image.rows >> top) < 1) {
    return fail(fmt::format("a {}x{} X-ray is too small for {} pyramid levels; use fewer levels", image.cols,
                            image.rows, levelCount));
  }
  XrayPyramid pyramid;
  pyramid.m_levels.reserve(static_cast<std::size_t>(levelCount));
  pyramid.m_levels.push_back(PyramidLevel{0, image, mask, camera});
  for (int k = 1; k < levelCount; ++k) {
    const PyramidLevel& below = pyramid.m_levels.back();
    PyramidLevel next{k, downsampleByTwo(below.image), downsampleByTwo(below.mask), std::nullopt};
    if (camera) next.camera = camera->downsampled(k);
    pyramid.m_levels.push_back(std::move(next));
  }
  return pyramid;
}

}  // namespace fct
