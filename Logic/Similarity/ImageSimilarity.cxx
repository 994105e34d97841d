#include "Similarity/ImageSimilarity.h"

#include <fmt/format.h>

#include <cmath>
#include <cstddef>

namespace fct {

Result<double> ImageSimilarity::evaluate(const FloatImage& drr) const {
  if (drr.cols != m_cols || drr.rows != m_rows) {
    return fail(fmt::format("DRR is {}x{} but the X-ray is {}x{}; render the DRR with this view's camera at the same "
                            "pyramid level",
                            drr.cols, drr.rows, m_cols, m_rows));
  }
  if (drr.pixels.size() != static_cast<std::size_t>(m_cols) * static_cast<std::size_t>(m_rows)) {
    return fail(fmt::format("DRR says {}x{} pixels but holds {} values; it is not a complete image", drr.cols, drr.rows,
                            drr.pixels.size()));
  }
  const double value = compare(drr);
  if (std::isnan(value)) {
    return fail(fmt::format("DRR has NaN or infinite values among the pixels {} compares; check the CT and the DRR "
                            "renderer",
                            name()));
  }
  return value;
}

}  // namespace fct
