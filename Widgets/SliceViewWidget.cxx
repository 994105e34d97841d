#include "Widgets/SliceViewWidget.h"

#include <QWheelEvent>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fct {

namespace {

constexpr int kMaxSliceSide_px = 1024;  ///< the slice image is at most this many pixels per side
const QString kCrosshairLayer = QStringLiteral("crosshair");

/// Trilinear value at continuous index ijk; NaN outside the voxel grid (half a voxel beyond the centres counts in).
float sampleTrilinear(const Volume& volume, const Eigen::Vector3d& ijk) {
  int i0[3];
  int i1[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    const int d = volume.dims()[a];
    const double x = ijk[a];
    if (!(x >= -0.5 && x <= d - 0.5)) return std::numeric_limits<float>::quiet_NaN();
    const double clamped = std::clamp(x, 0.0, static_cast<double>(d - 1));
    i0[a] = static_cast<int>(clamped);
    if (i0[a] >= d - 1) {
      i0[a] = i1[a] = d - 1;
      f[a] = 0.0;
    } else {
      i1[a] = i0[a] + 1;
      f[a] = clamped - i0[a];
    }
  }
  const auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double c00 = lerp(volume.at(i0[0], i0[1], i0[2]), volume.at(i1[0], i0[1], i0[2]), f[0]);
  const double c10 = lerp(volume.at(i0[0], i1[1], i0[2]), volume.at(i1[0], i1[1], i0[2]), f[0]);
  const double c01 = lerp(volume.at(i0[0], i0[1], i1[2]), volume.at(i1[0], i0[1], i1[2]), f[0]);
  const double c11 = lerp(volume.at(i0[0], i1[1], i1[2]), volume.at(i1[0], i1[1], i1[2]), f[0]);
  return static_cast<float>(lerp(lerp(c00, c10, f[1]), lerp(c01, c11, f[1]), f[2]));
}

}  // namespace

SliceViewWidget::SliceViewWidget(SliceOrientation orientation, QWidget* parent)
    : ImageViewWidget(parent), m_orientation(orientation) {
  switch (orientation) {
    case SliceOrientation::Axial:
      m_right = Eigen::Vector3d::UnitX();
      m_down = Eigen::Vector3d::UnitY();
      break;
    case SliceOrientation::Coronal:
      m_right = Eigen::Vector3d::UnitX();
      m_down = -Eigen::Vector3d::UnitZ();
      break;
    case SliceOrientation::Sagittal:
      m_right = Eigen::Vector3d::UnitY();
      m_down = -Eigen::Vector3d::UnitZ();
      break;
  }
  m_normal = m_right.cross(m_down);
  setPlaceholderText(orientationName(orientation) + tr(": no CT"));
  setTitle(orientationName(orientation));

  connect(this, &ImageViewWidget::pixelClicked, this, [this](const Eigen::Vector2d& uv_px) {
    if (m_ct) emit pointClicked(ctPointForPixel(uv_px));
  });
  connect(this, &ImageViewWidget::pixelHovered, this, [this](const Eigen::Vector2d& uv_px, float value) {
    if (m_ct) emit ctPointHovered(ctPointForPixel(uv_px), value);
  });
  connect(this, &ImageViewWidget::markerClicked, this, [this](const QString& layer, int index) {
    for (const CtLayer& l : m_ctLayers) {
      if (QStringLiteral("ct:") + l.name != layer || index < 0 || index >= static_cast<int>(l.shownIndex.size())) continue;
      emit ctPointClicked(l.name, l.shownIndex[static_cast<std::size_t>(index)]);
    }
  });
  connect(this, &ImageViewWidget::pointDragged, this, [this](const QString& layer, int index, const Eigen::Vector2d& uv_px) {
    for (const CtLayer& l : m_ctLayers) {
      if (QStringLiteral("ct:") + l.name != layer || index < 0 || index >= static_cast<int>(l.shownIndex.size())) continue;
      emit ctPointDragged(l.name, l.shownIndex[static_cast<std::size_t>(index)], ctPointForPixel(uv_px));
    }
  });
}

QString SliceViewWidget::orientationName(SliceOrientation orientation) {
  switch (orientation) {
    case SliceOrientation::Axial:
      return tr("Axial");
    case SliceOrientation::Coronal:
      return tr("Coronal");
    case SliceOrientation::Sagittal:
      return tr("Sagittal");
  }
  return {};
}

QString SliceViewWidget::sideCoordinate(int lpsAxis, double value_mm) {
  static const char* const kSides[3][2] = {{"R", "L"}, {"A", "P"}, {"I", "S"}};  // {negative, positive} side
  const int axis = std::clamp(lpsAxis, 0, 2);
  const double rounded = std::round(value_mm * 10.0) / 10.0;  // "L 0.0", never "R -0.0"
  return QStringLiteral("%1 %2").arg(QLatin1String(kSides[axis][rounded >= 0.0 ? 1 : 0])).arg(std::abs(rounded), 0, 'f', 1);
}

QString SliceViewWidget::positionText(const Eigen::Vector3d& p_ct_mm) {
  return tr("LPS (%1, %2, %3) mm = %4 %5 %6")
      .arg(p_ct_mm.x(), 0, 'f', 1)
      .arg(p_ct_mm.y(), 0, 'f', 1)
      .arg(p_ct_mm.z(), 0, 'f', 1)
      .arg(sideCoordinate(0, p_ct_mm.x()), sideCoordinate(1, p_ct_mm.y()), sideCoordinate(2, p_ct_mm.z()));
}

void SliceViewWidget::setVolume(std::shared_ptr<const Volume> ct) {
  m_ct = std::move(ct);
  if (!m_ct || m_ct->voxelCount() == 0) {
    m_ct.reset();
    clear();
    setTitle(orientationName(m_orientation));
    return;
  }
  const Volume& v = *m_ct;
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d high = -low;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d ijk((corner & 1) ? v.dims().x() - 0.5 : -0.5, (corner & 2) ? v.dims().y() - 0.5 : -0.5,
                              (corner & 4) ? v.dims().z() - 0.5 : -0.5);
    const Eigen::Vector3d p = v.lpsFromIjk(ijk);
    const Eigen::Vector3d q(m_right.dot(p), m_down.dot(p), m_normal.dot(p));
    low = low.cwiseMin(q);
    high = high.cwiseMax(q);
  }
  const double extent = std::max(high.x() - low.x(), high.y() - low.y());
  m_pixel_mm = std::max(v.spacing_mm().minCoeff(), extent / kMaxSliceSide_px);
  m_size_px = Eigen::Vector2i(std::max(1, static_cast<int>(std::ceil((high.x() - low.x()) / m_pixel_mm))),
                              std::max(1, static_cast<int>(std::ceil((high.y() - low.y()) / m_pixel_mm))));
  m_min_mm = Eigen::Vector2d(low.x() + 0.5 * m_pixel_mm, low.y() + 0.5 * m_pixel_mm);
  m_sliceStep_mm = 0.0;
  for (int a = 0; a < 3; ++a) m_sliceStep_mm += std::abs(m_normal.dot(v.direction_lps().col(a))) * v.spacing_mm()[a];
  m_crosshair_ct_mm = v.centre_lps_mm();

  clear();  // new size: layers are rebuilt below
  updateSlice();
  resetView();
  applyWindowPreset(SliceWindowPreset::Bone);
}

double SliceViewWidget::slicePosition_mm() const { return m_normal.dot(m_crosshair_ct_mm); }

void SliceViewWidget::setCrosshair_ct_mm(const Eigen::Vector3d& p_ct_mm) {
  if (!p_ct_mm.allFinite()) return;
  const bool newSlice = std::abs(m_normal.dot(p_ct_mm - m_crosshair_ct_mm)) > 1e-9;
  m_crosshair_ct_mm = p_ct_mm;
  if (!m_ct) return;
  if (newSlice) {
    updateSlice();
  } else {
    updateOverlays();
  }
}

void SliceViewWidget::scrollSlices(double steps) {
  if (!m_ct) return;
  // Keep the slice inside the volume along the normal.
  const Volume& v = *m_ct;
  double lowest = std::numeric_limits<double>::max();
  double highest = -lowest;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d ijk((corner & 1) ? v.dims().x() - 1 : 0, (corner & 2) ? v.dims().y() - 1 : 0,
                              (corner & 4) ? v.dims().z() - 1 : 0);
    const double s = m_normal.dot(v.lpsFromIjk(ijk));
    lowest = std::min(lowest, s);
    highest = std::max(highest, s);
  }
  const double now = slicePosition_mm();
  const double target = std::clamp(now + steps * m_sliceStep_mm, lowest, highest);
  m_crosshair_ct_mm += (target - now) * m_normal;
  updateSlice();
  emit crosshairMoved(m_crosshair_ct_mm);
}

void SliceViewWidget::applyWindowPreset(SliceWindowPreset preset) {
  switch (preset) {
    case SliceWindowPreset::Bone:
      setWindowLevel(1800.0, 400.0);
      break;
    case SliceWindowPreset::SoftTissue:
      setWindowLevel(400.0, 40.0);
      break;
  }
}

void SliceViewWidget::setCtPointLayer(const QString& name, std::vector<SlicePoint> points, bool draggable) {
  auto it = std::find_if(m_ctLayers.begin(), m_ctLayers.end(), [&](const CtLayer& l) { return l.name == name; });
  if (it == m_ctLayers.end()) {
    m_ctLayers.push_back(CtLayer{name, {}, false, {}});
    it = std::prev(m_ctLayers.end());
  }
  it->points = std::move(points);
  it->draggable = draggable;
  updateOverlays();
}

Eigen::Vector3d SliceViewWidget::ctPointForPixel(const Eigen::Vector2d& uv_px) const {
  return m_right * (m_min_mm.x() + uv_px.x() * m_pixel_mm) + m_down * (m_min_mm.y() + uv_px.y() * m_pixel_mm) +
         m_normal * slicePosition_mm();
}

Eigen::Vector2d SliceViewWidget::pixelForCtPoint(const Eigen::Vector3d& p_ct_mm) const {
  return {(m_right.dot(p_ct_mm) - m_min_mm.x()) / m_pixel_mm, (m_down.dot(p_ct_mm) - m_min_mm.y()) / m_pixel_mm};
}

QPoint SliceViewWidget::widgetPointForCtPoint(const Eigen::Vector3d& p_ct_mm) const {
  return widgetPointForPixel(pixelForCtPoint(p_ct_mm));
}

Eigen::Vector3d SliceViewWidget::ctPointForWidgetPoint(const QPointF& p_widget) const {
  return ctPointForPixel(pixelForWidgetPoint(p_widget));
}

void SliceViewWidget::updateSlice() {
  const Volume& v = *m_ct;
  FloatImage slice = FloatImage::filled(m_size_px.x(), m_size_px.y());
  const Eigen::Affine3d T_ijk_from_lps = v.T_ijk_from_lps();
  const Eigen::Vector3d dCol = T_ijk_from_lps.linear() * (m_right * m_pixel_mm);
  const Eigen::Vector3d dRow = T_ijk_from_lps.linear() * (m_down * m_pixel_mm);
  const Eigen::Vector3d start = T_ijk_from_lps * ctPointForPixel(Eigen::Vector2d::Zero());
  for (int row = 0; row < slice.rows; ++row) {
    Eigen::Vector3d ijk = start + row * dRow;
    for (int col = 0; col < slice.cols; ++col, ijk += dCol) slice.at(col, row) = sampleTrilinear(v, ijk);
  }
  const bool firstImage = !hasImage();
  setImage(slice, /*keepView=*/!firstImage);
  const int axis = m_orientation == SliceOrientation::Axial ? 2 : m_orientation == SliceOrientation::Coronal ? 1 : 0;
  setTitle(tr("%1  %2 mm (LPS %3 %4)")
               .arg(orientationName(m_orientation), sideCoordinate(axis, m_crosshair_ct_mm[axis]))
               .arg(QLatin1Char("xyz"[axis]))
               .arg(m_crosshair_ct_mm[axis], 0, 'f', 1));
  updateOverlays();
}

void SliceViewWidget::updateOverlays() {
  if (!m_ct) return;
  const Eigen::Vector2d c = pixelForCtPoint(m_crosshair_ct_mm);
  const double right = m_size_px.x() - 0.5;
  const double bottom = m_size_px.y() - 0.5;
  setPolylineLayer(kCrosshairLayer,
                   {{Eigen::Vector2d(-0.5, c.y()), Eigen::Vector2d(right, c.y())},
                    {Eigen::Vector2d(c.x(), -0.5), Eigen::Vector2d(c.x(), bottom)}},
                   QColor(255, 200, 60), 0.55, /*closed=*/false);
  const double plane = slicePosition_mm();
  for (CtLayer& l : m_ctLayers) {
    std::vector<OverlayPoint> shown;
    l.shownIndex.clear();
    for (std::size_t i = 0; i < l.points.size(); ++i) {
      const SlicePoint& point = l.points[i];
      if (std::abs(m_normal.dot(point.p_ct_mm) - plane) > 0.5 * m_sliceStep_mm + 1e-6) continue;
      shown.push_back(OverlayPoint{pixelForCtPoint(point.p_ct_mm), point.label, point.color});
      l.shownIndex.push_back(static_cast<int>(i));
    }
    setPointLayer(QStringLiteral("ct:") + l.name, std::move(shown), l.draggable);
  }
}

void SliceViewWidget::wheelEvent(QWheelEvent* event) {
  const double steps = event->angleDelta().y() / 120.0;
  if (event->modifiers() & Qt::ControlModifier) {
    zoomAbout(event->position(), steps);
  } else {
    scrollSlices(steps);
  }
  event->accept();
}

}  // namespace fct
