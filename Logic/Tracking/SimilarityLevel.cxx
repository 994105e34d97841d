#include "Tracking/SimilarityLevel.h"

#include <algorithm>

namespace fct {

SimilarityLevel::SimilarityLevel(double firstSimilarity, double growth, double weight)
    : m_anchor(firstSimilarity), m_running(firstSimilarity), m_growth(growth), m_weight(weight) {}

bool SimilarityLevel::holds(double similarity) const { return growthOf(similarity) <= m_growth; }

double SimilarityLevel::growthOf(double similarity) const { return (1.0 - similarity) / referenceDissimilarity(); }

void SimilarityLevel::follow(double similarity) { m_running = (1.0 - m_weight) * m_running + m_weight * similarity; }

double SimilarityLevel::referenceDissimilarity() const {
  return std::max(kMinReferenceDissimilarity, std::min(1.0 - m_running, 1.0 - m_anchor));
}

}  // namespace fct
