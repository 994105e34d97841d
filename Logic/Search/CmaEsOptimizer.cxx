#include "Search/CmaEsOptimizer.h"

#include <fmt/core.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "Base/SeededRandom.h"
#include "Search/ObjectiveEvaluator.h"

namespace fct {

namespace {
using Matrix6d = Eigen::Matrix<double, 6, 6>;
constexpr int kN = 6;
}  // namespace

Status CmaEsOptimizer::validateOptions() const {
  const auto& o = m_options;
  if (!std::isfinite(o.tolerance) || o.tolerance <= 0.0) {
    return fail(fmt::format("CMA-ES tolerance must be positive (scaled units), got {}", o.tolerance));
  }
  if (!std::isfinite(o.initialSigma) || o.initialSigma <= o.tolerance) {
    return fail(fmt::format("CMA-ES initial sigma {} must be larger than the tolerance {} (scaled units)",
                            o.initialSigma, o.tolerance));
  }
  if (o.populationSize != 0 && o.populationSize < 4) {
    return fail(fmt::format("CMA-ES population size must be 0 (default) or at least 4, got {}", o.populationSize));
  }
  if (o.maxEvaluations <= 0) {
    return fail(fmt::format("CMA-ES maximum evaluations must be positive, got {}", o.maxEvaluations));
  }
  return Ok{};
}

OptimizationResult CmaEsOptimizer::search(const PoseObjective& objective, const PoseVector& start,
                                          const PoseVector& scales, const ProgressMonitor& monitor) const {
  const auto& o = m_options;
  ObjectiveEvaluator evaluator(objective, start, scales, o.maxEvaluations, monitor);
  SeededRandom random(o.seed);

  // Strategy parameters (Hansen's tutorial defaults).
  const int lambda = o.populationSize > 0 ? o.populationSize : 4 + static_cast<int>(std::floor(3.0 * std::log(kN)));
  const int mu = lambda / 2;
  Eigen::VectorXd weights(mu);
  for (int i = 0; i < mu; ++i) weights[i] = std::log(0.5 * lambda + 0.5) - std::log(i + 1.0);
  weights /= weights.sum();
  const double muEff = 1.0 / weights.squaredNorm();
  const double cSigma = (muEff + 2.0) / (kN + muEff + 5.0);
  const double dSigma = 1.0 + 2.0 * std::max(0.0, std::sqrt((muEff - 1.0) / (kN + 1.0)) - 1.0) + cSigma;
  const double cC = (4.0 + muEff / kN) / (kN + 4.0 + 2.0 * muEff / kN);
  const double c1 = 2.0 / ((kN + 1.3) * (kN + 1.3) + muEff);
  const double cMu = std::min(1.0 - c1, 2.0 * (muEff - 2.0 + 1.0 / muEff) / ((kN + 2.0) * (kN + 2.0) + muEff));
  const double chiN = std::sqrt(static_cast<double>(kN)) * (1.0 - 1.0 / (4.0 * kN) + 1.0 / (21.0 * kN * kN));

  PoseVector mean = evaluator.toScaled(start);
  double sigma = o.initialSigma;
  Matrix6d C = Matrix6d::Identity();
  PoseVector pSigma = PoseVector::Zero(), pC = PoseVector::Zero();
  std::vector<PoseVector> z(lambda), y(lambda);
  std::vector<double> values(lambda);
  std::vector<int> order(lambda);
  std::vector<GenerationRecord> records;
  bool converged = false;

  for (int generation = 0; !evaluator.stopped(); ++generation) {
    const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(C);
    const Matrix6d B = eigen.eigenvectors();
    const PoseVector D = eigen.eigenvalues().cwiseMax(1e-300).cwiseSqrt();
    for (int k = 0; k < lambda; ++k) {
      for (int i = 0; i < kN; ++i) z[k][i] = random.normal();
      y[k] = B * D.cwiseProduct(z[k]);
      values[k] = evaluator.atScaled(mean + sigma * y[k]);
    }
    if (evaluator.cancelled()) break;
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return values[a] < values[b]; });

    PoseVector yW = PoseVector::Zero();
    for (int i = 0; i < mu; ++i) yW += weights[i] * y[order[i]];
    mean += sigma * yW;
    // C^(-1/2) yW = B D^-1 B^T yW
    const PoseVector invSqrtCyW = B * (B.transpose() * yW).cwiseQuotient(D);
    pSigma = (1.0 - cSigma) * pSigma + std::sqrt(cSigma * (2.0 - cSigma) * muEff) * invSqrtCyW;
    const double pSigmaNorm = pSigma.norm();
    const bool hSigma = pSigmaNorm / std::sqrt(1.0 - std::pow(1.0 - cSigma, 2.0 * (generation + 1))) / chiN <
                        1.4 + 2.0 / (kN + 1.0);
    pC = (1.0 - cC) * pC + (hSigma ? std::sqrt(cC * (2.0 - cC) * muEff) : 0.0) * yW;
    Matrix6d rankMu = Matrix6d::Zero();
    for (int i = 0; i < mu; ++i) rankMu += weights[i] * y[order[i]] * y[order[i]].transpose();
    C = (1.0 - c1 - cMu) * C + c1 * (pC * pC.transpose() + (hSigma ? 0.0 : cC * (2.0 - cC)) * C) + cMu * rankMu;
    C = 0.5 * (C + C.transpose());
    sigma *= std::exp((cSigma / dSigma) * (pSigmaNorm / chiN - 1.0));

    records.push_back({generation, evaluator.evaluations(), evaluator.bestValue(), lambda});
    monitor.report(name(), static_cast<double>(evaluator.evaluations()) / o.maxEvaluations,
                   fmt::format("generation {}, {} evaluations, best value {:.6g}, sigma {:.3g}", generation,
                               evaluator.evaluations(), evaluator.bestValue(), sigma));
    if (!std::isfinite(sigma) || sigma * std::sqrt(C.diagonal().maxCoeff()) < o.tolerance) {
      converged = std::isfinite(sigma);
      break;
    }
  }
  // The mean is usually better than any sample near convergence.
  if (!evaluator.stopped()) evaluator.atScaled(mean);

  OptimizationResult result = evaluator.result(converged);
  result.generations = std::move(records);
  return result;
}

}  // namespace fct
