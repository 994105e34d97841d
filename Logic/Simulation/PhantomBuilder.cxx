#include "Simulation/PhantomBuilder.h"

#include <fmt/core.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>

namespace fct {
namespace {

// All anatomy is laid out in "model mm" for a 160 x 160 x 120 mm field of view (LPS: +x patient left,
// +y posterior, +z superior) and scaled to the actual field of view.
constexpr double kReferenceHalfExtent_mm[3] = {80.0, 80.0, 60.0};
constexpr double kBodySemiAxisX = 74.0, kBodySemiAxisY = 64.0, kBodyCentreY = 5.0;
constexpr double kFatThickness = 6.0;
constexpr double kVertebraPeriod = 37.0;
constexpr double kVertebraCentreY = 10.0;
constexpr double kCorticalThickness = 1.6;

/// Depth inside an axis-aligned box (positive inside, approximately the distance to the nearest face).
double boxDepth(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  return std::min((p - lo).minCoeff(), (hi - p).minCoeff());
}

/// Depth inside an elliptic cross-section (semi-axes a, b) measured along the ray from its centre.
double ellipseDepth(double x, double y, double a, double b) {
  const double e = std::sqrt((x / a) * (x / a) + (y / b) * (y / b));
  if (e < 1e-9) return std::min(a, b);
  return (1.0 - e) * std::sqrt(x * x + y * y) / e;
}

/// Depth inside a cylinder of radius r around an axis, between two caps (distance along the axis in [lo, hi]).
double cylinderDepth(double radial, double along, double r, double lo, double hi) {
  return std::min(r - radial, std::min(along - lo, hi - along));
}

/// Uniform value in [-1, 1] from a voxel index and seed (integer hash: identical on every platform and thread).
float hashNoise(int i, int j, int k, std::uint32_t seed) {
  std::uint32_t h = seed * 0x9E3779B9u ^ static_cast<std::uint32_t>(i) * 0x85EBCA6Bu ^
                    static_cast<std::uint32_t>(j) * 0xC2B2AE35u ^ static_cast<std::uint32_t>(k) * 0x27D4EB2Fu;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  h *= 0x297A2D39u;
  h ^= h >> 15;
  return static_cast<float>(h) * (2.0f / 4294967295.0f) - 1.0f;
}

/// A plane wave cos(k . p + phase).
struct Wave {
  Eigen::Vector3d k;
  double phase;
  double at(const Eigen::Vector3d& p) const { return std::cos(k.dot(p) + phase); }
};

/// The seeded random parts: trabecular texture and slow soft-tissue variation.
class Texture {
 public:
  explicit Texture(std::uint32_t seed) {
    std::mt19937 rng(seed);
    const auto uniform = [&rng] { return static_cast<double>(rng() >> 8) * (1.0 / 16777216.0); };  // [0,1)
    const auto waves = [&](double wavelength_mm, auto& out) {
      for (Wave& w : out) {
        const double cosTheta = 2.0 * uniform() - 1.0;
        const double phi = 2.0 * std::numbers::pi * uniform();
        const double sinTheta = std::sqrt(1.0 - cosTheta * cosTheta);
        const Eigen::Vector3d dir(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta);
        w.k = (2.0 * std::numbers::pi / (wavelength_mm * (0.8 + 0.4 * uniform()))) * dir;
        w.phase = 2.0 * std::numbers::pi * uniform();
      }
    };
    waves(4.5, m_trabecular);
    waves(60.0, m_tissue);
  }
  /// Trabecular bone fraction in [0,1] at a model point: plates and rods about 2 mm apart.
  double trabecular(const Eigen::Vector3d& q) const {
    double s = 0.0;
    for (const Wave& w : m_trabecular) s += w.at(q);
    return 1.0 / (1.0 + std::exp(-2.0 * s));
  }
  /// Slow variation in [-1,1] for soft tissue and cortical density.
  double slow(const Eigen::Vector3d& q) const {
    double s = 0.0;
    for (const Wave& w : m_tissue) s += w.at(q);
    return s / static_cast<double>(m_tissue.size());
  }

 private:
  std::array<Wave, 6> m_trabecular;
  std::array<Wave, 3> m_tissue;
};

/// Bone depth of one vertebra at a point in its local frame (origin at the canal centre, mm; >0 inside bone).
double vertebraDepth(const Eigen::Vector3d& p) {
  const double x = p.x(), y = p.y(), z = p.z();
  double depth = -1e9;
  // Vertebral body: elliptic cylinder in front of the canal.
  depth = std::max(depth, std::min(ellipseDepth(x, y + 14.0, 22.0, 15.0), 13.5 - std::abs(z)));
  // Pedicles: cylinders along y at x = +-12.5; the left one has a nutrient hole along x.
  for (const double side : {-1.0, 1.0}) {
    const double radial = std::hypot(x - side * 12.5, z - 2.0);
    double pedicle = cylinderDepth(radial, y, 5.0, -2.0, 17.0);
    if (side > 0 && std::hypot(y - 7.0, z - 2.0) < 1.6) pedicle = std::min(pedicle, -1.0);
    depth = std::max(depth, pedicle);
  }
  // Lamina closing the canal behind.
  depth = std::max(depth, boxDepth(p, {-13.0, 15.0, -5.0}, {13.0, 21.0, 9.0}));
  // Spinous process: slab sloping down (caudally) and tapering, with a bulbous tip.
  if (y > 19.0 && y < 45.0) {
    const double t = y - 19.0;
    const double halfHeight = 7.0 - 0.08 * t;
    const double zc = 2.0 - 0.3 * t;
    depth = std::max(depth, std::min({3.5 - std::abs(x), halfHeight - std::abs(z - zc), y - 19.0, 45.0 - y}));
  }
  depth = std::max(depth, 4.5 - (p - Eigen::Vector3d(0.0, 44.0, 2.0 - 0.3 * 25.0)).norm());
  // Transverse processes: the left (+x) is longer and lower than the right.
  depth = std::max(depth, boxDepth(p, {12.0, 8.0, -1.0}, {40.0, 15.0, 7.0}));
  depth = std::max(depth, boxDepth(p, {-32.0, 8.0, 2.0}, {-12.0, 15.0, 9.0}));
  // Superior articular processes (only superiorly).
  for (const double side : {-1.0, 1.0}) {
    depth = std::max(depth, cylinderDepth(std::hypot(x - side * 15.0, y - 17.0), z, 3.5, 8.0, 17.0));
  }
  return depth;
}

/// Bone depth of the femur-like shaft (tilted tube on the patient's left with a posterior ridge and a nutrient
/// hole); marrow (inside the canal) is reported through `inCanal`.
double femurDepth(const Eigen::Vector3d& q, bool& inCanal) {
  const Eigen::Vector3d axisPoint(48.0, -8.0, 0.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(0.15, 0.05, 1.0).normalized();
  const Eigen::Vector3d rel = q - axisPoint;
  const Eigen::Vector3d radialVec = rel - rel.dot(axis) * axis;
  const double radial = radialVec.norm();
  inCanal = radial < 7.0;
  double depth = std::min(13.0 - radial, radial - 7.0);
  // Ridge (linea aspera) along the posterior side.
  if (radialVec.y() > 0.0 && std::abs(radialVec.x()) < 3.0) {
    depth = std::max(depth, std::min({16.5 - radial, 3.0 - std::abs(radialVec.x()), radial - 7.0}));
  }
  // Nutrient foramen through the anterior cortex at one level.
  if (radialVec.y() < 0.0 && std::hypot(radialVec.x(), rel.z() - 20.0) < 1.5) depth = std::min(depth, -1.0);
  return depth;
}

}  // namespace

Result<Volume> PhantomBuilder::build(const PhantomOptions& options) {
  const Eigen::Vector3i& dims = options.dims;
  if ((dims.array() <= 0).any()) {
    return fail(fmt::format("phantom dimensions must be positive, got {}x{}x{}", dims.x(), dims.y(), dims.z()));
  }
  if (!std::isfinite(options.spacing_mm) || options.spacing_mm <= 0.0) {
    return fail(fmt::format("phantom spacing must be a positive number of mm, got {}", options.spacing_mm));
  }
  const double voxels = static_cast<double>(dims.x()) * dims.y() * dims.z();
  if (voxels > static_cast<double>(1 << 30)) {
    return fail(fmt::format("a {}x{}x{} phantom needs {:.1f} GB; use at most 2^30 voxels (e.g. 1024x1024x1024)",
                            dims.x(), dims.y(), dims.z(), voxels * 4.0 / 1e9));
  }
  const Eigen::Vector3d spacing = Eigen::Vector3d::Constant(options.spacing_mm);
  const Eigen::Vector3d halfExtent_mm = 0.5 * (dims.cast<double>() - Eigen::Vector3d::Ones()) * options.spacing_mm;
  auto created = Volume::create(dims, spacing, -halfExtent_mm);
  if (!created.ok()) return created;
  Volume volume = std::move(created.value());

  // Model mm per volume mm: fit the reference field of view into the actual one, keeping proportions.
  double fit = 1e300;
  for (int a = 0; a < 3; ++a) {
    fit = std::min(fit, std::max(halfExtent_mm[a], 0.5 * options.spacing_mm) / kReferenceHalfExtent_mm[a]);
  }
  const double modelPerMm = 1.0 / fit;
  // Keep the cortical shell at least about one voxel thick so it survives coarse sampling.
  const double cortex = std::max(kCorticalThickness, 1.2 * options.spacing_mm * modelPerMm);
  const Texture texture(options.seed);
  const std::uint32_t seed = options.seed;

  tbb::parallel_for(0, dims.z(), [&](int k) {
    for (int j = 0; j < dims.y(); ++j) {
      for (int i = 0; i < dims.x(); ++i) {
        const Eigen::Vector3d q = modelPerMm * volume.lpsFromIjk(Eigen::Vector3d(i, j, k));
        const float noise = hashNoise(i, j, k, seed);
        float hu = -1000.0f;
        const double skinDepth = ellipseDepth(q.x(), q.y() - kBodyCentreY, kBodySemiAxisX, kBodySemiAxisY);
        if (skinDepth > 0.0) {
          hu = skinDepth < kFatThickness ? -100.0f + 8.0f * noise
                                         : static_cast<float>(20.0 + 10.0 * texture.slow(q)) + 5.0f * noise;
          // Bone: the vertebra nearest in z (scaled larger inferiorly) and the femur-like shaft.
          const int level = std::clamp(static_cast<int>(std::lround(q.z() / kVertebraPeriod)), -1, 1);
          const double scale = 1.0 - 0.06 * level;
          const Eigen::Vector3d local(q.x(), q.y() - kVertebraCentreY, q.z() - level * kVertebraPeriod);
          double depth = scale * vertebraDepth(local / scale);
          bool inCanal = false;
          const double femur = femurDepth(q, inCanal);
          const bool discLevel = std::abs(q.z()) < kVertebraPeriod;
          if (femur > depth) depth = femur;
          if (depth > 0.0) {
            const double shell = 1.0 - std::min(depth / cortex, 1.0);
            hu = depth < cortex ? static_cast<float>(1450.0 + 200.0 * shell + 100.0 * texture.slow(q)) + 30.0f * noise
                                : static_cast<float>(200.0 + 200.0 * texture.trabecular(q)) + 15.0f * noise;
          } else if (inCanal) {
            hu = -60.0f + 10.0f * noise;  // fatty marrow
          } else if (discLevel && ellipseDepth(local.x(), local.y() + 14.0, 21.0, 14.0) > 0.0) {
            hu = 80.0f + 8.0f * noise;  // intervertebral disc
          }
        }
        volume.at(i, j, k) = hu;
      }
    }
  });
  volume.description = fmt::format("FluoroCT phantom (lumbar spine and femur-like shaft), seed {}, {}x{}x{} at {} mm",
                                   options.seed, dims.x(), dims.y(), dims.z(), options.spacing_mm);
  return volume;
}

}  // namespace fct
