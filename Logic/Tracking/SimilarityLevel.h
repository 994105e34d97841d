#pragma once
// SimilarityLevel: the similarity half of the lost-track rule. It keeps the running level of the tracked frames'
// similarity (an exponential mean) and an anchor level (frame 0's), and judges a frame by its dissimilarity
// 1 - similarity against the smaller of the two levels' dissimilarities: a track that drifts off lowers its similarity
// over several frames, and a reference that followed it down would never flag it. The image content can lower the
// similarity too (the bone moves to where soft tissue or the field's edge spoils the match); when a re-registration
// confirms the tracked pose of a frame whose similarity fell gradually (fellGradually), the tracker moves the levels to
// it (reanchor), and the next frames are judged against the new scene.

namespace fct {

/// The running similarity level of a track and the test of a new frame against it.
class SimilarityLevel {
 public:
  /// The floor of the reference dissimilarity: a frame with similarity >= 1 - growth x this always holds (near-perfect
  /// matches differ only by noise).
  static constexpr double kMinReferenceDissimilarity = 0.005;

  /// A placeholder until frame 0's similarity is known (CineTracker replaces it in trackFirst, before any judgement).
  SimilarityLevel() = default;
  /// Starts both levels (running and anchor) at frame 0's similarity; `growth` (> 1) is the tolerated growth of the
  /// dissimilarity, `weight` (0 < w <= 1) a new frame's weight in the running level. Callers check the ranges
  /// (CineTracker::create).
  SimilarityLevel(double firstSimilarity, double growth, double weight);

  /// True when 1 - similarity <= growth x referenceDissimilarity() (false for NaN).
  bool holds(double similarity) const;
  /// True when 1 - similarity <= growth x max(kMinReferenceDissimilarity, 1 - the last trusted frame's similarity)
  /// (false for NaN): the similarity fell gradually, as it does when the scene changes, not at once, as it does when a
  /// track jumps off or a frame is garbled.
  bool fellGradually(double similarity) const;
  /// Makes `similarity` every level's value (a re-registration confirmed a frame's pose with it): the next frames are
  /// judged against that frame's scene, not frame 0's.
  void reanchor(double similarity) { m_anchor = m_running = m_last = similarity; }
  /// Folds a trusted frame's similarity into the running level; it becomes the last trusted frame's.
  void follow(double similarity);
  /// The last trusted frame's similarity (frame 0's at the start).
  double last() const { return m_last; }
  /// The running level (exponential mean of the trusted frames' similarity, frame 0 included).
  double running() const { return m_running; }
  /// max(kMinReferenceDissimilarity, min(1 - running level, 1 - anchor level)).
  double referenceDissimilarity() const;

 private:
  double m_anchor = 0.0;  ///< frame 0's similarity, or the last re-anchored frame's
  double m_running = 0.0;
  double m_last = 0.0;
  double m_growth = 1.0;
  double m_weight = 1.0;
};

}  // namespace fct
