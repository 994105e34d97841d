#pragma once
// ImageSimilarity: the common interface of the similarity metrics between one view's X-ray (fixed, prepared once
// when the metric is created) and a DRR of the same size (evaluated for every pose). Higher is more similar; every
// metric is in [-1, 1] and invariant to a gain and offset of either image.
//
// evaluate() is the one entry point: it checks the DRR once (its size, and that the compared values are finite) and
// runs the variant's compare(). A variant implements compare() and name() only. One virtual call per DRR, none per
// pixel.

#include <string>

#include "Base/Result.h"
#include "Image/FloatImage.h"

namespace fct {

/// A similarity measure against a fixed X-ray.
class ImageSimilarity {
 public:
  virtual ~ImageSimilarity() = default;

  /// Similarity of `drr` to the X-ray, in [-1, 1]. Fails, naming both sizes, when `drr` is not the X-ray's size; fails
  /// when its pixel buffer does not match its size, or when a DRR value the measure compares is NaN or infinite.
  Result<double> evaluate(const FloatImage& drr) const;
  /// Short name for reports ("NCC", "VLNC", "GC").
  virtual std::string name() const = 0;
  /// Columns of the X-ray, and so of every DRR compared with it.
  int cols() const { return m_cols; }
  /// Rows of the X-ray, and so of every DRR compared with it.
  int rows() const { return m_rows; }

 protected:
  /// A measure against an X-ray of `xrayCols` x `xrayRows` pixels.
  ImageSimilarity(int xrayCols, int xrayRows) : m_cols(xrayCols), m_rows(xrayRows) {}

  /// The measure of `drr`, which evaluate() has checked to be cols() x rows() with a matching buffer; in [-1, 1], or
  /// NaN when a compared DRR value is not finite.
  virtual double compare(const FloatImage& drr) const = 0;

 private:
  int m_cols;
  int m_rows;
};

}  // namespace fct
