#include "XrayPrep/DewarpCalibrator.h"

#include <fmt/core.h>

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <optional>

namespace fct {

namespace {

constexpr int kFolds = 5;
constexpr int kMaxAutoDegree = 7;
constexpr double kMinMagnification = 0.9;
constexpr double kMaxMagnification = 1.8;

/// Median of the values (0 for none).
double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// Index of the bead nearest to `p`, and its distance; -1 for no beads.
std::pair<int, double> nearest(const std::vector<PixelCircle>& beads, const Eigen::Vector2d& p, int skip = -1) {
  int best = -1;
  double bestDistance = std::numeric_limits<double>::infinity();
  for (int b = 0; b < static_cast<int>(beads.size()); ++b) {
    if (b == skip) continue;
    const double d = (beads[b].centre_px - p).norm();
    if (d < bestDistance) {
      bestDistance = d;
      best = b;
    }
  }
  return {best, bestDistance};
}

/// Beads with their lattice indices, grown breadth-first from the bead nearest the image centre.
struct Lattice {
  std::vector<DewarpBead> beads;
  double pitch_px = 0.0;
  int unindexed = 0;
};

Result<Lattice> indexLattice(const std::vector<PixelCircle>& found, const Eigen::Vector2d& centre_px) {
  constexpr int kMinBeads = 9;
  if (static_cast<int>(found.size()) < kMinBeads) {
    return fail(fmt::format("no calibration grid found: {} bead shadow{} detected, at least {} needed; check that the "
                            "image shows the plate's beads as dark dots",
                            found.size(), found.size() == 1 ? "" : "s", kMinBeads));
  }
  std::vector<double> spacing;
  for (int b = 0; b < static_cast<int>(found.size()); ++b) spacing.push_back(nearest(found, found[b].centre_px, b).second);
  Lattice lattice;
  lattice.pitch_px = median(spacing);
  const double tolerance = 0.3 * lattice.pitch_px;
  const int origin = nearest(found, centre_px).first;

  // The two axes: neighbours of the centre bead at about one pitch, the first nearest to +column, the second the
  // one nearest to 90 degrees from it towards +row.
  std::vector<Eigen::Vector2d> steps;
  for (const PixelCircle& bead : found) {
    const Eigen::Vector2d step = bead.centre_px - found[origin].centre_px;
    if (std::abs(step.norm() - lattice.pitch_px) < tolerance) steps.push_back(step);
  }
  const auto angleFromColumn = [](const Eigen::Vector2d& v) { return std::abs(std::atan2(v.y(), v.x())); };
  if (steps.size() < 2) {
    return fail(fmt::format("no calibration grid found: the bead nearest the image centre has {} neighbour{} at the "
                            "grid's pitch of {:.1f} px; the beads do not form a square grid",
                            steps.size(), steps.size() == 1 ? "" : "s", lattice.pitch_px));
  }
  const Eigen::Vector2d e1 = *std::min_element(steps.begin(), steps.end(), [&](const auto& a, const auto& b) {
    return angleFromColumn(a) < angleFromColumn(b);
  });
  Eigen::Vector2d e2 = Eigen::Vector2d::Zero();
  double bestAngleError = 0.35;  // radians, about 20 degrees
  for (const Eigen::Vector2d& step : steps) {
    const double cross = e1.x() * step.y() - e1.y() * step.x();
    const double angle = std::atan2(cross, e1.dot(step));
    if (std::abs(angle - M_PI / 2) < bestAngleError) {
      bestAngleError = std::abs(angle - M_PI / 2);
      e2 = step;
    }
  }
  if (e2.isZero()) {
    return fail(fmt::format("no calibration grid found: the centre bead's neighbours at the pitch of {:.1f} px include "
                            "no two at right angles; the beads do not form a square grid",
                            lattice.pitch_px));
  }

  struct Node {
    int bead;
    std::array<int, 2> index;
    Eigen::Vector2d e1, e2;
  };
  std::vector<int> indexOf(found.size(), -1);
  std::map<std::array<int, 2>, int> taken;
  std::deque<Node> queue{{origin, {0, 0}, e1, e2}};
  indexOf[origin] = 0;
  taken[{0, 0}] = origin;
  lattice.beads.push_back({found[origin].centre_px, {0, 0}, Eigen::Vector2d::Zero(), 0.0, true});
  while (!queue.empty()) {
    const Node node = queue.front();
    queue.pop_front();
    const Eigen::Vector2d here = found[node.bead].centre_px;
    const std::array<std::array<int, 2>, 4> moves{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
    for (const auto& move : moves) {
      const std::array<int, 2> index{node.index[0] + move[0], node.index[1] + move[1]};
      if (taken.count(index)) continue;
      const Eigen::Vector2d predicted = here + move[0] * node.e1 + move[1] * node.e2;
      const auto [bead, distance] = nearest(found, predicted);
      if (distance > tolerance || indexOf[bead] >= 0) continue;
      Node next{bead, index, node.e1, node.e2};
      const Eigen::Vector2d step = found[bead].centre_px - here;
      if (move[0] != 0) next.e1 = move[0] * step;
      if (move[1] != 0) next.e2 = move[1] * step;
      indexOf[bead] = static_cast<int>(lattice.beads.size());
      taken[index] = bead;
      lattice.beads.push_back({found[bead].centre_px, index, Eigen::Vector2d::Zero(), 0.0, true});
      queue.push_back(next);
    }
  }
  lattice.unindexed = static_cast<int>(found.size() - lattice.beads.size());
  return lattice;
}

/// A fitted field with its lattice similarity g(i, j) = t + [a −b; b a] (i, j).
struct Fit {
  Eigen::VectorXd col_px, row_px;
  double a = 1.0, b = 0.0;
  Eigen::Vector2d t = Eigen::Vector2d::Zero();

  Eigen::Vector2d lattice(const std::array<int, 2>& ij) const {
    return t + Eigen::Vector2d(a * ij[0] - b * ij[1], b * ij[0] + a * ij[1]);
  }
};

/// Unknowns of a degree's fit: two coefficient vectors and the similarity's four parameters.
int unknownCount(int degree) { return 2 * static_cast<int>(DewarpField::terms(degree).size()) + 4; }

/// Least-squares fit over the beads for which `include(k)` is true.
template <typename Include>
Fit fitBeads(const DewarpField& shape, const std::vector<DewarpBead>& beads, Include include) {
  const int terms = static_cast<int>(DewarpField::terms(shape.degree()).size());
  const int unknowns = 2 * terms + 4;
  int count = 0;
  for (std::size_t k = 0; k < beads.size(); ++k) count += include(k) ? 1 : 0;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * count, unknowns);
  Eigen::VectorXd rhs(2 * count);
  int row = 0;
  for (std::size_t k = 0; k < beads.size(); ++k) {
    if (!include(k)) continue;
    const DewarpBead& bead = beads[k];
    const Eigen::VectorXd basis = shape.radius_px() * shape.basis(bead.distorted_px);
    const double i = bead.lattice[0], j = bead.lattice[1];
    // col: d_x + R basis·c_col = a i − b j + t_x;  row: d_y + R basis·c_row = b i + a j + t_y
    A.block(row, 0, 1, terms) = basis.transpose();
    A(row, 2 * terms + 0) = -i;
    A(row, 2 * terms + 1) = j;
    A(row, 2 * terms + 2) = -1.0;
    rhs[row] = -bead.distorted_px.x();
    A.block(row + 1, terms, 1, terms) = basis.transpose();
    A(row + 1, 2 * terms + 0) = -j;
    A(row + 1, 2 * terms + 1) = -i;
    A(row + 1, 2 * terms + 3) = -1.0;
    rhs[row + 1] = -bead.distorted_px.y();
    row += 2;
  }
  const Eigen::VectorXd x = A.colPivHouseholderQr().solve(rhs);
  Fit fit;
  fit.col_px = x.segment(0, terms);
  fit.row_px = x.segment(terms, terms);
  fit.a = x[2 * terms];
  fit.b = x[2 * terms + 1];
  fit.t = Eigen::Vector2d(x[2 * terms + 2], x[2 * terms + 3]);
  return fit;
}

/// The field of a fit (the shape gives the size and degree); nullopt when the fit is not finite (degenerate beads).
std::optional<DewarpField> fieldOf(const DewarpField& shape, const Fit& fit) {
  auto field = DewarpField::create(shape.cols(), shape.rows(), shape.degree(), fit.col_px, fit.row_px);
  if (!field || !std::isfinite(fit.a) || !std::isfinite(fit.b) || !fit.t.allFinite()) return std::nullopt;
  return std::move(field).value();
}

/// The error of a fit that the beads do not determine.
Error undeterminedFit(int degree) {
  return fail(fmt::format("the beads do not determine a degree-{} dewarp (the fit is singular); use a plate whose "
                          "grid covers the whole image, or a lower --degree",
                          degree));
}

/// Residual of bead k under a fit.
double residual(const DewarpField& field, const Fit& fit, const DewarpBead& bead) {
  return (field.ideal(bead.distorted_px) - fit.lattice(bead.lattice)).norm();
}

/// RMS of bead residuals over the used beads, predicted by a fit that left out one fold at a time.
double crossValidatedRms(const DewarpField& shape, const std::vector<DewarpBead>& beads) {
  double sum = 0.0;
  int count = 0;
  for (int fold = 0; fold < kFolds; ++fold) {
    const Fit fit = fitBeads(shape, beads, [&](std::size_t k) { return beads[k].used && int(k % kFolds) != fold; });
    const auto field = fieldOf(shape, fit);
    if (!field) return std::numeric_limits<double>::infinity();
    for (std::size_t k = fold; k < beads.size(); k += kFolds) {
      if (!beads[k].used) continue;
      const double r = residual(*field, fit, beads[k]);
      sum += r * r;
      ++count;
    }
  }
  return count ? std::sqrt(sum / count) : 0.0;
}

/// Number of used beads.
int usedCount(const std::vector<DewarpBead>& beads) {
  return static_cast<int>(std::count_if(beads.begin(), beads.end(), [](const DewarpBead& b) { return b.used; }));
}

/// Beads needed for a degree: three equations (two per bead) per unknown.
int beadsNeeded(int degree) { return (3 * unknownCount(degree) + 1) / 2; }

}  // namespace

Result<DewarpCalibrationResult> DewarpCalibrator::calibrate(const FloatImage& grid, const ValidMask& mask) const {
  const DewarpCalibrationOptions& o = m_options;
  if (!(o.pitch_mm > 0.0 && std::isfinite(o.pitch_mm))) {
    return fail(fmt::format("grid pitch must be a positive number of mm, got {}", o.pitch_mm));
  }
  if (!(o.pixelSpacing_mm >= 0.0 && std::isfinite(o.pixelSpacing_mm))) {
    return fail(fmt::format("pixel spacing must be positive (or 0 for unknown), got {} mm", o.pixelSpacing_mm));
  }
  if (o.degree != 0 && (o.degree < DewarpField::kMinDegree || o.degree > DewarpField::kMaxDegree)) {
    return fail(fmt::format("dewarp degree must be {}..{} (or 0 to choose), got {}", DewarpField::kMinDegree,
                            DewarpField::kMaxDegree, o.degree));
  }
  auto found = GridBeadDetector(o.beads).detect(grid, mask);
  if (!found) return fail(found.error());
  auto lattice = indexLattice(found.value(), Eigen::Vector2d(0.5 * (grid.cols - 1), 0.5 * (grid.rows - 1)));
  if (!lattice) return fail(lattice.error());
  std::vector<DewarpBead> beads = std::move(lattice.value().beads);

  const int smallest = o.degree ? o.degree : 3;
  if (static_cast<int>(beads.size()) < beadsNeeded(smallest)) {
    return fail(fmt::format("too few beads: {} beads lie on the grid around the centre bead, a degree-{} dewarp needs "
                            "at least {}; use a plate with a finer pitch that covers the whole image{}",
                            beads.size(), smallest, beadsNeeded(smallest), o.degree ? " or a lower --degree" : ""));
  }

  // Outliers: from a fit of a middle degree, drop beads beyond max(0.5 px, 5 robust sigmas) once.
  int screenDegree = o.degree ? o.degree : 5;
  while (screenDegree > smallest && static_cast<int>(beads.size()) < beadsNeeded(screenDegree)) --screenDegree;
  {
    const DewarpField shape = DewarpField::identity(grid.cols, grid.rows, screenDegree).value();
    const Fit fit = fitBeads(shape, beads, [](std::size_t) { return true; });
    const auto field = fieldOf(shape, fit);
    if (!field) return undeterminedFit(screenDegree);
    std::vector<double> residuals;
    for (const DewarpBead& bead : beads) residuals.push_back(residual(*field, fit, bead));
    const double limit = std::max(0.5, 5.0 * 1.4826 * median(residuals));
    for (std::size_t k = 0; k < beads.size(); ++k) beads[k].used = residuals[k] <= limit;
  }
  const int used = usedCount(beads);
  if (used < beadsNeeded(smallest)) {
    return fail(fmt::format("too few beads: {} of {} grid beads fit a smooth distortion, a degree-{} dewarp needs at "
                            "least {}; check the grid image for overlapping objects",
                            used, beads.size(), smallest, beadsNeeded(smallest)));
  }

  DewarpCalibrationResult result;
  const int lowest = o.degree ? o.degree : DewarpField::kMinDegree;
  const int highest = o.degree ? o.degree : kMaxAutoDegree;
  for (int degree = lowest; degree <= highest && used >= beadsNeeded(degree); ++degree) {
    const DewarpField shape = DewarpField::identity(grid.cols, grid.rows, degree).value();
    const Fit fit = fitBeads(shape, beads, [&](std::size_t k) { return beads[k].used; });
    const auto field = fieldOf(shape, fit);
    if (!field) continue;  // a degree the beads do not determine is not a candidate
    double sum = 0.0;
    for (const DewarpBead& bead : beads) sum += bead.used ? std::pow(residual(*field, fit, bead), 2) : 0.0;
    result.degrees.push_back({degree, std::sqrt(sum / used), o.degree ? 0.0 : crossValidatedRms(shape, beads)});
  }
  if (result.degrees.empty()) return undeterminedFit(lowest);
  int chosen = o.degree;
  if (!chosen) {
    double best = std::numeric_limits<double>::infinity();
    for (const DewarpDegreeResidual& d : result.degrees) best = std::min(best, d.crossValidatedRms_px);
    for (const DewarpDegreeResidual& d : result.degrees) {
      if (d.crossValidatedRms_px <= 1.02 * best) chosen = d.degree;
    }
  }

  const DewarpField shape = DewarpField::identity(grid.cols, grid.rows, chosen).value();
  const Fit fit = fitBeads(shape, beads, [&](std::size_t k) { return beads[k].used; });
  const auto field = fieldOf(shape, fit);
  if (!field) return undeterminedFit(chosen);
  result.field = *field;
  double sum = 0.0, largest = 0.0;
  for (DewarpBead& bead : beads) {
    bead.ideal_px = fit.lattice(bead.lattice);
    bead.residual_px = residual(result.field, fit, bead);
    if (!bead.used) continue;
    sum += bead.residual_px * bead.residual_px;
    largest = std::max(largest, bead.residual_px);
  }
  DewarpCalibration& record = result.record;
  record.pitch_mm = o.pitch_mm;
  record.latticePitch_px = std::hypot(fit.a, fit.b);
  record.latticeRotation_deg = std::atan2(fit.b, fit.a) * 180.0 / M_PI;
  record.magnification = o.pixelSpacing_mm > 0.0 ? record.latticePitch_px * o.pixelSpacing_mm / o.pitch_mm : 0.0;
  record.beadCount = used;
  record.rejectedBeadCount = static_cast<int>(beads.size()) - used;
  record.rmsResidual_px = std::sqrt(sum / used);
  record.maxResidual_px = largest;
  if (o.pixelSpacing_mm > 0.0 &&
      !(record.magnification >= kMinMagnification && record.magnification <= kMaxMagnification)) {
    return fail(fmt::format("the grid's beads are {:.2f} px = {:.2f} mm apart on the detector, which for a pitch of {} "
                            "mm is a magnification of {:.2f}; a plate on the detector magnifies by {}..{}: check the "
                            "pitch and the pixel spacing ({} mm)",
                            record.latticePitch_px, record.latticePitch_px * o.pixelSpacing_mm, o.pitch_mm,
                            record.magnification, kMinMagnification, kMaxMagnification, o.pixelSpacing_mm));
  }
  result.beads = std::move(beads);
  result.unindexedBeadCount = lattice.value().unindexed;
  return result;
}

}  // namespace fct
