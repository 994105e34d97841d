#include "Drr/DrrVolume.h"

#include <fmt/core.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "Base/LargePages.h"
#include "Base/NameTable.h"

namespace fct {

Result<DrrVolume> DrrVolume::prepare(const Volume& ct, const DrrValueOptions& options) {
  if (ct.voxelCount() == 0) return fail("the CT volume is empty; load a CT before rendering DRRs");
  if (options.kind == DrrValueKind::Attenuation &&
      (!std::isfinite(options.waterAttenuation_per_mm) || options.waterAttenuation_per_mm <= 0.0)) {
    return fail(fmt::format("water attenuation must be positive and finite, got {} /mm", options.waterAttenuation_per_mm));
  }
  if (options.kind == DrrValueKind::Attenuation &&
      !DrrValueOptions::acceptsBoneContrast(options.boneContrast)) {
    return fail(fmt::format("bone contrast must be above 0 and at most {:g}, got {}", DrrValueOptions::kMaxBoneContrast,
                            options.boneContrast));
  }
  DrrVolume volume;
  volume.m_options = options;
  volume.m_T_ct_from_ijk = ct.T_lps_from_ijk();
  volume.m_T_ijk_from_ct = ct.T_ijk_from_lps();
  return volume;
}

Result<DrrVolume> DrrVolume::create(const Volume& ct, const DrrValueOptions& options) {
  auto volume = prepare(ct, options);
  if (!volume) return volume;
  // A fresh large-page grid of the CT's geometry, filled by the parallel conversion (no serial copy of the CT).
  auto grid = Volume::create(ct.dims(), ct.spacing_mm(), ct.origin_lps_mm(), ct.direction_lps());
  if (!grid) return fail(grid.error());
  volume.value().m_values = std::move(grid).value();
  volume.value().m_values.description = ct.description;
  volume.value().m_values.dicom = ct.dicom;
  if (Status converted = volume.value().convertFrom(ct.voxels()); !converted) return fail(converted.error());
  return volume;
}

Result<DrrVolume> DrrVolume::create(Volume&& ct, const DrrValueOptions& options) {
  auto volume = prepare(ct, options);
  if (!volume) return volume;
  volume.value().m_values = std::move(ct);
  const std::vector<float>& inPlace = volume.value().m_values.voxels();
  if (Status converted = volume.value().convertFrom(inPlace); !converted) return fail(converted.error());
  return volume;
}

Status DrrVolume::convertFrom(const std::vector<float>& hu) {
  std::vector<float>& voxels = m_values.voxels();
  const float mu_water = static_cast<float>(m_options.waterAttenuation_per_mm);
  const float boneFrom = static_cast<float>(DrrValueOptions::kBoneFrom_hu);
  const float boneSlope = static_cast<float>(m_options.boneContrast) * 0.001f;  // per HU above boneFrom
  const bool attenuation = m_options.kind == DrrValueKind::Attenuation;
  // Each voxel is read before it is written, so `hu` may be `voxels` itself.
  const std::size_t nonFinite = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, voxels.size(), 1 << 16), std::size_t{0},
      [&](const tbb::blocked_range<std::size_t>& range, std::size_t count) {
        for (std::size_t n = range.begin(); n != range.end(); ++n) {
          const float value = hu[n];
          if (!std::isfinite(value)) {
            ++count;
            voxels[n] = 0.0f;
          } else if (attenuation) {
            const float bone = std::max(value - boneFrom, 0.0f);
            voxels[n] = value <= -1000.0f ? 0.0f : mu_water * (1.0f + (value - bone) * 0.001f + bone * boneSlope);
          } else {
            voxels[n] = value;
          }
        }
        return count;
      },
      std::plus<>());
  if (nonFinite > 0) {
    return fail(fmt::format("the CT has {} voxels that are NaN or infinite; repair or re-export the volume", nonFinite));
  }
  findContentBox();
  return Ok{};
}

Result<DrrVolume> DrrVolume::coarsened(const Eigen::Vector3i& blockSize_ijk) const {
  if ((blockSize_ijk.array() < 1).any()) {
    return fail(fmt::format("CT block size must be at least 1 voxel per axis, got {}x{}x{}", blockSize_ijk.x(),
                            blockSize_ijk.y(), blockSize_ijk.z()));
  }
  const Eigen::Vector3i& fine = dims();
  const Eigen::Vector3i coarse = (fine + blockSize_ijk - Eigen::Vector3i::Ones()).cwiseQuotient(blockSize_ijk);
  // The first coarse voxel's centre is the centre of its block's voxels.
  const Eigen::Vector3d firstCentre_ijk = 0.5 * (blockSize_ijk - Eigen::Vector3i::Ones()).cast<double>();
  auto grid = Volume::create(coarse, m_values.spacing_mm().cwiseProduct(blockSize_ijk.cast<double>()),
                             m_values.lpsFromIjk(firstCentre_ijk), m_values.direction_lps());
  if (!grid) return fail("coarse CT: " + grid.error());
  DrrVolume volume;
  volume.m_values = std::move(grid).value();
  volume.m_options = m_options;
  volume.m_T_ct_from_ijk = volume.m_values.T_lps_from_ijk();
  volume.m_T_ijk_from_ct = volume.m_values.T_ijk_from_lps();
  const float weight = 1.0f / static_cast<float>(blockSize_ijk.prod());
  tbb::parallel_for(0, coarse.z(), [&](int K) {
    for (int k = K * blockSize_ijk.z(); k < std::min(fine.z(), (K + 1) * blockSize_ijk.z()); ++k) {
      for (int j = 0; j < fine.y(); ++j) {
        const float* row = data() + m_values.offset(0, j, k);
        float* coarseRow = &volume.m_values.at(0, j / blockSize_ijk.y(), K);
        for (int i = 0; i < fine.x(); ++i) coarseRow[i / blockSize_ijk.x()] += weight * row[i];
      }
    }
  });
  volume.findContentBox();
  return volume;
}

DrrVolume DrrVolume::sliceAveragesDeconvolved() const {
  DrrVolume volume;
  volume.m_values = m_values;
  volume.m_options = m_options;
  volume.m_T_ct_from_ijk = m_T_ct_from_ijk;
  volume.m_T_ijk_from_ct = m_T_ijk_from_ct;
  // The tridiagonal system is the same for every column: Thomas's forward factors are computed once, then every
  // row of i values is swept forward and back along k (rows of one j in parallel; each row is contiguous).
  const int nk = dims().z();
  constexpr double kNeighbour = 1.0 / 8.0;
  std::vector<double> upper(nk), pivotInverse(nk);
  for (int k = 0; k < nk; ++k) {
    const double diagonal = 0.75 + (k == 0 ? kNeighbour : 0.0) + (k == nk - 1 ? kNeighbour : 0.0);
    const double pivot = diagonal - (k > 0 ? kNeighbour * upper[k - 1] : 0.0);
    pivotInverse[k] = 1.0 / pivot;
    upper[k] = kNeighbour / pivot;
  }
  const int ni = dims().x();
  tbb::parallel_for(0, dims().y(), [&](int j) {
    std::vector<double> solved(static_cast<std::size_t>(ni) * nk);
    for (int k = 0; k < nk; ++k) {
      const float* row = data() + m_values.offset(0, j, k);
      double* out = solved.data() + static_cast<std::size_t>(k) * ni;
      if (k == 0) {
        for (int i = 0; i < ni; ++i) out[i] = row[i] * pivotInverse[0];
        continue;
      }
      const double* previous = out - ni;
      for (int i = 0; i < ni; ++i) out[i] = (row[i] - kNeighbour * previous[i]) * pivotInverse[k];
    }
    for (int k = nk - 2; k >= 0; --k) {
      double* out = solved.data() + static_cast<std::size_t>(k) * ni;
      const double* next = out + ni;
      for (int i = 0; i < ni; ++i) out[i] -= upper[k] * next[i];
    }
    for (int k = 0; k < nk; ++k) {
      float* row = &volume.m_values.at(0, j, k);
      const double* out = solved.data() + static_cast<std::size_t>(k) * ni;
      for (int i = 0; i < ni; ++i) row[i] = static_cast<float>(out[i]);
    }
  });
  volume.findContentBox();
  return volume;
}

const float* DrrVolume::valuesJFastest() const {
  std::call_once(m_jFastest->made, [this] {
    const Eigen::Vector3i& n = dims();
    m_jFastest->values = allocateWithLargePages(m_values.voxelCount());  // every value is written below
    const float* source = data();
    float* target = m_jFastest->values.get();
    constexpr int kBlock = 16;  // i values per task: one cache line of each source row
    const int blocks = (n.x() + kBlock - 1) / kBlock;
    tbb::parallel_for(tbb::blocked_range<int>(0, n.z() * blocks), [&](const tbb::blocked_range<int>& tasks) {
      for (int task = tasks.begin(); task != tasks.end(); ++task) {
        const int k = task / blocks;
        const int i0 = (task - k * blocks) * kBlock, i1 = std::min(n.x(), i0 + kBlock);
        for (int j = 0; j < n.y(); ++j) {
          const float* row = source + m_values.offset(0, j, k);
          for (int i = i0; i < i1; ++i) target[j + n.y() * (i + static_cast<std::ptrdiff_t>(n.x()) * k)] = row[i];
        }
      }
    });
  });
  return m_jFastest->values.get();
}

void DrrVolume::findContentBox() {
  const Eigen::Vector3i n = dims();
  const std::vector<float>& voxels = m_values.voxels();
  struct Box {
    Eigen::Vector3i first = Eigen::Vector3i::Constant(std::numeric_limits<int>::max());
    Eigen::Vector3i last = Eigen::Vector3i::Constant(-1);
    Box merged(const Box& other) const { return {first.cwiseMin(other.first), last.cwiseMax(other.last)}; }
  };
  const Box box = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, n.z()), Box{},
      [&](const tbb::blocked_range<int>& slices, Box box) {
        for (int k = slices.begin(); k != slices.end(); ++k) {
          for (int j = 0; j < n.y(); ++j) {
            const float* row = voxels.data() + m_values.offset(0, j, k);
            int i = 0;
            while (i < n.x() && row[i] == 0.0f) ++i;
            if (i == n.x()) continue;
            int last = n.x() - 1;
            while (row[last] == 0.0f) --last;
            box.first = box.first.cwiseMin(Eigen::Vector3i(i, j, k));
            box.last = box.last.cwiseMax(Eigen::Vector3i(last, j, k));
          }
        }
        return box;
      },
      [](const Box& a, const Box& b) { return a.merged(b); });
  m_contentFirst_ijk = box.last.x() < 0 ? Eigen::Vector3i::Zero() : box.first;
  m_contentLast_ijk = box.last;
}

namespace {

/// The names of the DRR value kinds on the command line and in files.
constexpr NameTable<DrrValueKind, 2> kValueKinds{
    {{"attenuation", DrrValueKind::Attenuation}, {"raw", DrrValueKind::Raw}}};

}  // namespace

Result<DrrValueKind> DrrVolume::parseValueKind(std::string_view name) {
  if (const auto kind = valueNamed(name, kValueKinds)) return *kind;
  return fail(fmt::format("unknown DRR values '{}'; use 'attenuation' or 'raw'", name));
}

std::string_view DrrVolume::valueKindName(DrrValueKind kind) {
  return nameOf(kind, kValueKinds);
}

}  // namespace fct
