#include "Simulation/ForeignObjectSet.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "Base/JsonDocument.h"
#include "Base/SeededRandom.h"

namespace fct {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Length of [t0, t1] ∩ [0, ∞).
double clippedLength(double t0, double t1) { return std::max(0.0, t1 - std::max(t0, 0.0)); }

/// Chord length of a ray through a sphere.
double sphereChord(const ForeignObject& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const Eigen::Vector3d w = o - s.a_mm;
  const double b = w.dot(d);
  const double disc = b * b - (w.squaredNorm() - s.radius_mm * s.radius_mm);
  if (disc <= 0.0) return 0.0;
  const double root = std::sqrt(disc);
  return clippedLength(-b - root, -b + root);
}

/// Chord length of a ray through a finite cylinder (axis a -> b, flat ends).
double cylinderChord(const ForeignObject& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const Eigen::Vector3d axis = c.b_mm - c.a_mm;
  const double length = axis.norm();
  const Eigen::Vector3d u = axis / length;
  const Eigen::Vector3d w = o - c.a_mm;
  const double wu = w.dot(u), du = d.dot(u);
  // Along the axis: 0 <= wu + t du <= length.
  double t0 = -kInf, t1 = kInf;
  if (std::abs(du) < 1e-15) {
    if (wu < 0.0 || wu > length) return 0.0;
  } else {
    t0 = (0.0 - wu) / du;
    t1 = (length - wu) / du;
    if (t0 > t1) std::swap(t0, t1);
  }
  // Across the axis: |w⊥ + t d⊥| <= r.
  const Eigen::Vector3d wp = w - wu * u, dp = d - du * u;
  const double a = dp.squaredNorm(), b = wp.dot(dp), cc = wp.squaredNorm() - c.radius_mm * c.radius_mm;
  if (a < 1e-15) {
    if (cc > 0.0) return 0.0;
  } else {
    const double disc = b * b - a * cc;
    if (disc <= 0.0) return 0.0;
    const double root = std::sqrt(disc);
    t0 = std::max(t0, (-b - root) / a);
    t1 = std::min(t1, (-b + root) / a);
  }
  return t1 > t0 ? clippedLength(t0, t1) : 0.0;
}

/// Chord length of a ray through an oriented box.
double boxChord(const ForeignObject& box, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const Eigen::Vector3d ob = box.axes.transpose() * (o - box.a_mm), db = box.axes.transpose() * d;
  double t0 = -kInf, t1 = kInf;
  for (int k = 0; k < 3; ++k) {
    const double h = box.halfExtent_mm[k];
    if (std::abs(db[k]) < 1e-15) {
      if (std::abs(ob[k]) > h) return 0.0;
      continue;
    }
    double s0 = (-h - ob[k]) / db[k], s1 = (h - ob[k]) / db[k];
    if (s0 > s1) std::swap(s0, s1);
    t0 = std::max(t0, s0);
    t1 = std::min(t1, s1);
  }
  return t1 > t0 ? clippedLength(t0, t1) : 0.0;
}

/// A uniformly random unit vector.
Eigen::Vector3d randomUnit(SeededRandom& random) {
  const double z = random.uniform(-1.0, 1.0), phi = random.uniform(0.0, 2.0 * M_PI);
  const double r = std::sqrt(1.0 - z * z);
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// `direction` tilted by a random angle up to maxAngle_rad in a random plane.
Eigen::Vector3d jitter(const Eigen::Vector3d& direction, double maxAngle_rad, SeededRandom& random) {
  Eigen::Vector3d side = direction.cross(randomUnit(random));
  if (side.norm() < 1e-6) side = direction.unitOrthogonal();
  return Eigen::AngleAxisd(random.uniform(0.0, maxAngle_rad), side.normalized()) * direction;
}

/// Where implants go on a CT's bone: the bone centroid and the surface voxels nearest to it.
struct ImplantSites {
  Eigen::Vector3d centroid_mm = Eigen::Vector3d::Zero();  ///< LPS
  std::vector<Eigen::Vector3i> surface;  ///< voxel indices: the half of the surface nearest the centroid
};

/// The bone centroid and surface voxels (bone with a non-bone 6-neighbour; the grid border counts as non-bone) of
/// `ct`, keeping the half of the surface voxels nearest the centroid (where the C-arm looks). Fails when no voxel is
/// bone.
Result<ImplantSites> findImplantSites(const Volume& ct, double boneThreshold_hu) {
  const Eigen::Vector3i& dims = ct.dims();
  const auto isBone = [&](int i, int j, int k) {
    return i >= 0 && j >= 0 && k >= 0 && i < dims.x() && j < dims.y() && k < dims.z() &&
           ct.at(i, j, k) >= boneThreshold_hu;
  };
  Eigen::Vector3d sum_ijk = Eigen::Vector3d::Zero();
  double boneCount = 0.0;
  ImplantSites sites;
  for (int k = 0; k < dims.z(); ++k) {
    for (int j = 0; j < dims.y(); ++j) {
      for (int i = 0; i < dims.x(); ++i) {
        if (!isBone(i, j, k)) continue;
        sum_ijk += Eigen::Vector3d(i, j, k);
        boneCount += 1.0;
        if (!isBone(i - 1, j, k) || !isBone(i + 1, j, k) || !isBone(i, j - 1, k) || !isBone(i, j + 1, k) ||
            !isBone(i, j, k - 1) || !isBone(i, j, k + 1)) {
          sites.surface.emplace_back(i, j, k);
        }
      }
    }
  }
  if (sites.surface.empty()) {
    return fail(fmt::format("no bone (voxels >= {} HU) to place K-wires, screws, a plate or gas pockets near; lower "
                            "the bone threshold or drop the objects",
                            boneThreshold_hu));
  }
  sites.centroid_mm = ct.lpsFromIjk(sum_ijk / boneCount);
  const auto distance2 = [&](const Eigen::Vector3i& v) {
    return (ct.lpsFromIjk(v.cast<double>()) - sites.centroid_mm).squaredNorm();
  };
  const auto middle = sites.surface.begin() + static_cast<std::ptrdiff_t>(sites.surface.size() / 2);
  std::nth_element(sites.surface.begin(), middle, sites.surface.end(),
                   [&](const Eigen::Vector3i& a, const Eigen::Vector3i& b) { return distance2(a) < distance2(b); });
  sites.surface.erase(middle + 1, sites.surface.end());
  return sites;
}

/// The centre (LPS mm) of a random one of the sites' surface voxels.
Eigen::Vector3d randomSurfacePoint(const Volume& ct, const ImplantSites& sites, SeededRandom& random) {
  return ct.lpsFromIjk(sites.surface[random.index(static_cast<int>(sites.surface.size()))].cast<double>());
}

/// The unit vector from the bone centroid to p_mm; a random one when p_mm is the centroid.
Eigen::Vector3d outwardAt(const ImplantSites& sites, const Eigen::Vector3d& p_mm, SeededRandom& random) {
  const Eigen::Vector3d v = p_mm - sites.centroid_mm;
  return v.norm() > 1e-6 ? Eigen::Vector3d(v.normalized()) : randomUnit(random);
}

/// A steel K-wire (r 1 mm, 150 mm long) through a random surface point, pointing outward ±30°, tip 25 mm inside.
ForeignObject placeKwire(const Volume& ct, const ImplantSites& sites, SeededRandom& random) {
  const Eigen::Vector3d p = randomSurfacePoint(ct, sites, random);
  const Eigen::Vector3d dir = jitter(outwardAt(sites, p, random), M_PI / 6.0, random);
  ForeignObject wire;
  wire.kind = "kwire";
  wire.shape = ForeignObject::Shape::Cylinder;
  wire.material = Material::Iron;
  wire.a_mm = p - 25.0 * dir;
  wire.b_mm = p + 125.0 * dir;
  wire.radius_mm = 1.0;
  return wire;
}

/// A titanium screw at a random surface point pointing inward ±20°: its shaft (r 2.25 mm, 40 mm into the bone) and
/// its head (r 4 mm, 3.5 mm outside the surface).
std::pair<ForeignObject, ForeignObject> placeScrew(const Volume& ct, const ImplantSites& sites, SeededRandom& random) {
  const Eigen::Vector3d p = randomSurfacePoint(ct, sites, random);
  const Eigen::Vector3d dir = jitter(-outwardAt(sites, p, random), M_PI / 9.0, random);
  ForeignObject shaft;
  shaft.kind = "screw_shaft";
  shaft.shape = ForeignObject::Shape::Cylinder;
  shaft.material = Material::Titanium;
  shaft.density_g_per_cm3 = MassAttenuationTable::density_g_per_cm3(Material::Titanium);
  shaft.a_mm = p;
  shaft.b_mm = p + 40.0 * dir;
  shaft.radius_mm = 2.25;
  ForeignObject head = shaft;
  head.kind = "screw_head";
  head.a_mm = p - 3.5 * dir;
  head.b_mm = p;
  head.radius_mm = 4.0;
  return {shaft, head};
}

/// A steel plate (100 × 12 × 3.5 mm) lying on a random surface point, its long axis along the CT's k axis (its i axis
/// when k is nearly along the surface normal).
ForeignObject placePlate(const Volume& ct, const ImplantSites& sites, SeededRandom& random) {
  const Eigen::Vector3d p = randomSurfacePoint(ct, sites, random);
  const Eigen::Vector3d normal = outwardAt(sites, p, random);
  Eigen::Vector3d along = ct.direction_lps().col(2) - normal * normal.dot(ct.direction_lps().col(2));
  if (along.norm() < 0.1) along = ct.direction_lps().col(0) - normal * normal.dot(ct.direction_lps().col(0));
  along.normalize();
  ForeignObject plate;
  plate.kind = "plate";
  plate.shape = ForeignObject::Shape::Box;
  plate.material = Material::Iron;
  plate.axes.col(0) = along;
  plate.axes.col(1) = normal.cross(along);
  plate.axes.col(2) = normal;
  plate.halfExtent_mm = Eigen::Vector3d(50.0, 6.0, 1.75);
  plate.a_mm = p + normal * 2.0;
  return plate;
}

/// True when the voxel nearest p_mm (LPS) is inside the grid and soft tissue (-200..300 HU, exclusive).
bool isSoftTissue(const Volume& ct, const Eigen::Vector3d& p_mm) {
  const Eigen::Vector3i ijk = ct.ijkFromLps(p_mm).array().round().cast<int>();
  if ((ijk.array() < 0).any() || (ijk.array() >= ct.dims().array()).any()) return false;
  const float hu = ct.at(ijk.x(), ijk.y(), ijk.z());
  return hu > -200.0f && hu < 300.0f;
}

/// A gas pocket: of up to 500 random spheres (r 8..20 mm, centre within 100 mm of centroid_mm), the first whose centre
/// and 26 surface points all lie in soft tissue; none when no attempt fits.
std::optional<ForeignObject> placeGasPocket(const Volume& ct, const Eigen::Vector3d& centroid_mm,
                                            SeededRandom& random) {
  for (int attempt = 0; attempt < 500; ++attempt) {
    const Eigen::Vector3d centre = centroid_mm + randomUnit(random) * random.uniform(0.0, 100.0);
    const double radius = random.uniform(8.0, 20.0);
    bool placed = isSoftTissue(ct, centre);
    for (int a = -1; a <= 1 && placed; ++a) {
      for (int b = -1; b <= 1 && placed; ++b) {
        for (int c = -1; c <= 1 && placed; ++c) {
          if (a != 0 || b != 0 || c != 0) {
            placed = isSoftTissue(ct, centre + radius * Eigen::Vector3d(a, b, c).normalized());
          }
        }
      }
    }
    if (placed) {
      ForeignObject pocket;
      pocket.kind = "gas_pocket";
      pocket.shape = ForeignObject::Shape::Sphere;
      pocket.material = Material::SoftTissue;
      pocket.density_g_per_cm3 = -1.0;
      pocket.a_mm = centre;
      pocket.radius_mm = radius;
      return pocket;
    }
  }
  return std::nullopt;
}

}  // namespace

Result<ForeignObjectSet> ForeignObjectSet::placeNearBone(const Volume& ct, const ImplantOptions& options) {
  const auto badCount = [](int n) { return n < 0 || n > 20; };
  if (badCount(options.kwireCount) || badCount(options.screwCount) || badCount(options.gasPocketCount)) {
    return fail(fmt::format("K-wire, screw and gas-pocket counts must be 0..20, got {}, {} and {}", options.kwireCount,
                            options.screwCount, options.gasPocketCount));
  }
  ForeignObjectSet set;
  if (options.kwireCount == 0 && options.screwCount == 0 && !options.plate && options.gasPocketCount == 0) return set;
  auto bone = findImplantSites(ct, options.boneThreshold_hu);
  if (!bone.ok()) return fail(bone.error());

  SeededRandom random(options.seed);
  for (int n = 0; n < options.kwireCount; ++n) set.m_objects.push_back(placeKwire(ct, bone.value(), random));
  for (int n = 0; n < options.screwCount; ++n) {
    const auto [shaft, head] = placeScrew(ct, bone.value(), random);
    set.m_objects.push_back(shaft);
    set.m_objects.push_back(head);
  }
  if (options.plate) set.m_objects.push_back(placePlate(ct, bone.value(), random));
  for (int n = 0; n < options.gasPocketCount; ++n) {
    const std::optional<ForeignObject> pocket = placeGasPocket(ct, bone.value().centroid_mm, random);
    if (!pocket) return fail("found no soft tissue near the bone for a gas pocket; remove the gas pockets for this CT");
    set.m_objects.push_back(*pocket);
  }
  return set;
}

Result<ForeignObjectSet> ForeignObjectSet::calibrationGrid(const Camera& camera, double spacing_mm, double radius_mm,
                                                           double distanceFromDetector_mm) {
  const CameraIntrinsics& in = camera.intrinsics();
  const double z = in.sourceToDetector_mm - distanceFromDetector_mm;
  if (!(spacing_mm > 0.0 && radius_mm > 0.0 && std::isfinite(spacing_mm) && std::isfinite(radius_mm)) ||
      spacing_mm <= 2.0 * radius_mm) {
    return fail(fmt::format("calibration grid needs a positive sphere radius below half the pitch, got radius {} mm "
                            "and pitch {} mm",
                            radius_mm, spacing_mm));
  }
  if (!(z > 0.0 && distanceFromDetector_mm > 0.0)) {
    return fail(fmt::format("calibration grid distance from the detector must be in (0, {}) mm, got {}",
                            in.sourceToDetector_mm, distanceFromDetector_mm));
  }
  const Eigen::Matrix3d K = camera.K();
  const double magnification = in.sourceToDetector_mm / z;
  const double halfWidth_mm = std::max(in.cols * in.pixelSpacing_mm.x(), in.rows * in.pixelSpacing_mm.y()) / magnification;
  const int steps = static_cast<int>(std::ceil(halfWidth_mm / spacing_mm)) + 1;
  ForeignObjectSet set;
  for (int b = -steps; b <= steps; ++b) {
    for (int a = -steps; a <= steps; ++a) {
      const Eigen::Vector3d centre(a * spacing_mm, b * spacing_mm, z);
      const Eigen::Vector3d uvw = K * centre;
      const Eigen::Vector2d uv = uvw.head<2>() / uvw.z();
      const double shadow_px = radius_mm * magnification / in.pixelSpacing_mm.minCoeff() + 2.0;
      if (uv.x() < shadow_px || uv.y() < shadow_px || uv.x() > in.cols - 1 - shadow_px ||
          uv.y() > in.rows - 1 - shadow_px) {
        continue;
      }
      ForeignObject sphere;
      sphere.kind = "sphere";
      sphere.shape = ForeignObject::Shape::Sphere;
      sphere.material = Material::Iron;
      sphere.a_mm = centre;
      sphere.radius_mm = radius_mm;
      set.m_objects.push_back(sphere);
    }
  }
  return set;
}

void ForeignObjectSet::accumulate(const Eigen::Vector3d& origin_mm, const Eigen::Vector3d& direction,
                                  MassPaths& paths) const {
  for (const ForeignObject& object : m_objects) {
    double chord_mm = 0.0;
    switch (object.shape) {
      case ForeignObject::Shape::Sphere: chord_mm = sphereChord(object, origin_mm, direction); break;
      case ForeignObject::Shape::Cylinder: chord_mm = cylinderChord(object, origin_mm, direction); break;
      case ForeignObject::Shape::Box: chord_mm = boxChord(object, origin_mm, direction); break;
    }
    if (chord_mm > 0.0) {
      paths[static_cast<int>(object.material)] += object.density_g_per_cm3 * chord_mm * 0.1;
    }
  }
}

nlohmann::ordered_json ForeignObjectSet::toJson() const {
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  for (const ForeignObject& object : m_objects) {
    nlohmann::ordered_json entry;
    entry["kind"] = object.kind;
    entry["material"] = std::string(MassAttenuationTable::name(object.material));
    entry["density_g_per_cm3"] = object.density_g_per_cm3;
    switch (object.shape) {
      case ForeignObject::Shape::Sphere:
        entry["centre_mm"] = JsonDocument::array(object.a_mm);
        entry["radius_mm"] = object.radius_mm;
        break;
      case ForeignObject::Shape::Cylinder:
        entry["from_mm"] = JsonDocument::array(object.a_mm);
        entry["to_mm"] = JsonDocument::array(object.b_mm);
        entry["radius_mm"] = object.radius_mm;
        break;
      case ForeignObject::Shape::Box:
        entry["centre_mm"] = JsonDocument::array(object.a_mm);
        entry["axes"] = JsonDocument::array(object.axes);
        entry["half_extent_mm"] = JsonDocument::array(object.halfExtent_mm);
        break;
    }
    list.push_back(std::move(entry));
  }
  return list;
}

}  // namespace fct
