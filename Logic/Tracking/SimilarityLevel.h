#pragma once
// SimilarityLevel: the similarity half of the lost-track rule. It keeps the running level of the tracked frames'
// similarity (an exponential mean) and frame 0's, and judges a frame by its dissimilarity 1 - similarity against the
// smaller of the two levels' dissimilarities: a track that drifts off lowers its similarity over several frames, and a
// reference that followed it down would never flag it.

namespace fct {

/// The running similarity level of a track and the test of a new frame against it.
class SimilarityLevel {
 public:
  /// The floor of the reference dissimilarity: a frame with similarity >= 1 - growth x this always holds (near-perfect
  /// matches differ only by noise).
  static constexpr double kMinReferenceDissimilarity = 0.005;

  /// A placeholder until frame 0's similarity is known (CineTracker replaces it in trackFirst, before any judgement).
  SimilarityLevel() = default;
  /// Starts both levels at frame 0's similarity; `growth` (> 1) is the tolerated growth of the dissimilarity, `weight`
  /// (0 < w <= 1) a new frame's weight in the running level. Callers check the ranges (CineTracker::create).
  SimilarityLevel(double firstSimilarity, double growth, double weight);

  /// True when 1 - similarity <= growth x referenceDissimilarity() (false for NaN).
  bool holds(double similarity) const;
  /// Folds a trusted frame's similarity into the running level.
  void follow(double similarity);
  /// The running level (exponential mean of the trusted frames' similarity, frame 0 included).
  double running() const { return m_running; }
  /// max(kMinReferenceDissimilarity, min(1 - running level, 1 - frame 0's similarity)).
  double referenceDissimilarity() const;

 private:
  double m_first = 0.0;
  double m_running = 0.0;
  double m_growth = 1.0;
  double m_weight = 1.0;
};

}  // namespace fct
