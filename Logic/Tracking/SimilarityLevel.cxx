#include "Tracking/SimilarityLevel.h"

#include <algorithm>

namespace fct {

SimilarityLevel::SimilarityLevel(double firstSimilarity, double growth, double weight)
    : m_anchor(firstSimilarity),
      m_running(firstSimilarity),
      m_last(firstSimilarity),
      m_growth(growth),
      m_weight(weight) {}

bool SimilarityLevel::holds(double similarity) const {
  return 1.0 - similarity <= m_growth * referenceDissimilarity();
}

bool SimilarityLevel::fellGradually(double similarity) const {
  return 1.0 - similarity <= m_growth * std::max(kMinReferenceDissimilarity, 1.0 - m_last);
}

void SimilarityLevel::follow(double similarity) {
  m_running = (1.0 - m_weight) * m_running + m_weight * similarity;
  m_last = similarity;
}

double SimilarityLevel::referenceDissimilarity() const {
  return std::max(kMinReferenceDissimilarity, std::min(1.0 - m_running, 1.0 - m_anchor));
}

}  // namespace fct
