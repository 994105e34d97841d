#include "Widgets/ImageViewWidget.h"

#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>

namespace fct {

namespace {

constexpr double kClickTolerance_px = 4.0;  ///< a press and release closer than this is a click, not a drag
constexpr double kPickRadius_px = 8.0;      ///< how near a draggable point a press must be to grab it
constexpr double kPointRadius_px = 5.0;     ///< drawn radius of an overlay point
constexpr int kMaxLabelWidth_px = 90;       ///< widest a point label is drawn; longer ones are elided

}  // namespace

double ImageViewWidget::quantile(const std::vector<float>& values, double q) {
  const std::size_t step = std::max<std::size_t>(1, values.size() / 65536);
  std::vector<float> sample;
  sample.reserve(values.size() / step + 1);
  for (std::size_t i = 0; i < values.size(); i += step) {
    if (std::isfinite(values[i])) sample.push_back(values[i]);
  }
  if (sample.empty()) return 0.0;
  const auto k = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * static_cast<double>(sample.size() - 1));
  std::nth_element(sample.begin(), sample.begin() + static_cast<std::ptrdiff_t>(k), sample.end());
  return sample[k];
}

ImageViewWidget::ImageViewWidget(QWidget* parent) : QWidget(parent) {
  setMouseTracking(true);
  setFocusPolicy(Qt::ClickFocus);
  setMinimumSize(160, 120);
  setAttribute(Qt::WA_OpaquePaintEvent);
}

void ImageViewWidget::setImage(const FloatImage& image, bool keepView) {
  const bool sameSize = image.cols == m_image.cols && image.rows == m_image.rows;
  m_image = image;
  if (!(keepView && sameSize)) {
    m_zoom = 1.0;
    m_pan = QPointF(0.0, 0.0);
    resetWindowLevel();
  } else {
    updateGrey();
    update();
  }
}

void ImageViewWidget::setPlaceholderText(const QString& text) {
  m_placeholder = text;
  update();
}

void ImageViewWidget::clear() {
  m_image = FloatImage{};
  m_grey = QImage();
  m_layers.clear();
  m_drag = DragMode::None;
  update();
}

void ImageViewWidget::setTitle(const QString& title) {
  m_title = title;
  update();
}

void ImageViewWidget::setWindowLevel(double window, double level) {
  if (!std::isfinite(window) || !std::isfinite(level)) return;
  m_window = std::max(window, 1e-6);
  m_level = level;
  updateGrey();
  update();
  emit windowLevelChanged(m_window, m_level);
}

void ImageViewWidget::resetWindowLevel() {
  if (m_image.empty()) {
    setWindowLevel(1.0, 0.5);
    return;
  }
  const double low = quantile(m_image.pixels, 0.01);
  const double high = quantile(m_image.pixels, 0.99);
  const double window = high > low ? high - low : std::max(1.0, std::abs(high));
  setWindowLevel(window, 0.5 * (low + high));
}

void ImageViewWidget::setZoom(double zoom) {
  if (!std::isfinite(zoom)) return;
  m_zoom = std::clamp(zoom, 0.05, 100.0);
  update();
}

void ImageViewWidget::setPan(const QPointF& pan_widget_px) {
  m_pan = pan_widget_px;
  update();
}

void ImageViewWidget::resetView() {
  m_zoom = 1.0;
  m_pan = QPointF(0.0, 0.0);
  update();
}

ImageViewWidget::Layer* ImageViewWidget::findLayer(const QString& name) {
  for (Layer& l : m_layers) {
    if (l.name == name) return &l;
  }
  return nullptr;
}

const ImageViewWidget::Layer* ImageViewWidget::findLayer(const QString& name) const {
  for (const Layer& l : m_layers) {
    if (l.name == name) return &l;
  }
  return nullptr;
}

ImageViewWidget::Layer& ImageViewWidget::layer(const QString& name, LayerKind kind) {
  Layer* existing = findLayer(name);
  if (!existing) {
    m_layers.push_back(Layer{});
    existing = &m_layers.back();
    existing->name = name;
  }
  const bool visible = existing->visible;
  *existing = Layer{};
  existing->name = name;
  existing->kind = kind;
  existing->visible = visible;
  return *existing;
}

void ImageViewWidget::setPointLayer(const QString& name, std::vector<OverlayPoint> points, bool draggable) {
  if (m_drag == DragMode::Point) m_drag = DragMode::None;  // the dragged point may be gone
  Layer& l = layer(name, LayerKind::Points);
  l.points = std::move(points);
  l.draggable = draggable;
  update();
}

void ImageViewWidget::setPolylineLayer(const QString& name, std::vector<std::vector<Eigen::Vector2d>> polylines_px,
                                      QColor color, double opacity, bool closed) {
  Layer& l = layer(name, LayerKind::Polylines);
  l.polylines = std::move(polylines_px);
  l.color = color;
  l.opacity = std::clamp(opacity, 0.0, 1.0);
  l.closed = closed;
  update();
}

void ImageViewWidget::setImageLayer(const QString& name, QImage argb, double opacity) {
  if (argb.width() != m_image.cols || argb.height() != m_image.rows) {
    clearLayer(name);
    return;
  }
  Layer& l = layer(name, LayerKind::Image);
  l.image = std::move(argb);
  l.opacity = std::clamp(opacity, 0.0, 1.0);
  update();
}

void ImageViewWidget::setLayerVisible(const QString& name, bool visible) {
  if (Layer* l = findLayer(name)) {
    l->visible = visible;
    update();
  }
}

bool ImageViewWidget::isLayerVisible(const QString& name) const {
  const Layer* l = findLayer(name);
  return l && l->visible;
}

bool ImageViewWidget::hasLayer(const QString& name) const { return findLayer(name) != nullptr; }

void ImageViewWidget::clearLayer(const QString& name) {
  const auto it = std::find_if(m_layers.begin(), m_layers.end(), [&](const Layer& l) { return l.name == name; });
  if (it == m_layers.end()) return;
  if (m_drag == DragMode::Point) m_drag = DragMode::None;
  m_layers.erase(it);
  update();
}

std::vector<OverlayPoint> ImageViewWidget::layerPoints(const QString& name) const {
  const Layer* l = findLayer(name);
  return l && l->kind == LayerKind::Points ? l->points : std::vector<OverlayPoint>{};
}

double ImageViewWidget::scale() const {
  if (m_image.empty()) return 1.0;
  const double fit = std::min(static_cast<double>(width()) / m_image.cols, static_cast<double>(height()) / m_image.rows);
  return std::max(fit, 1e-6) * m_zoom;
}

QPointF ImageViewWidget::imageCorner() const {
  const double s = scale();
  return QPointF(0.5 * width() - 0.5 * s * m_image.cols, 0.5 * height() - 0.5 * s * m_image.rows) + m_pan;
}

QPoint ImageViewWidget::widgetPointForPixel(const Eigen::Vector2d& uv_px) const {
  const double s = scale();
  const QPointF corner = imageCorner();
  return QPointF(corner.x() + s * (uv_px.x() + 0.5), corner.y() + s * (uv_px.y() + 0.5)).toPoint();
}

Eigen::Vector2d ImageViewWidget::pixelForWidgetPoint(const QPointF& p_widget) const {
  const double s = scale();
  const QPointF corner = imageCorner();
  return {(p_widget.x() - corner.x()) / s - 0.5, (p_widget.y() - corner.y()) / s - 0.5};
}

void ImageViewWidget::updateGrey() {
  if (m_image.empty()) {
    m_grey = QImage();
    return;
  }
  if (m_grey.width() != m_image.cols || m_grey.height() != m_image.rows) {
    m_grey = QImage(m_image.cols, m_image.rows, QImage::Format_Grayscale8);
  }
  const float low = static_cast<float>(m_level - 0.5 * m_window);
  const float gain = static_cast<float>(255.0 / m_window);
  for (int row = 0; row < m_image.rows; ++row) {
    uchar* line = m_grey.scanLine(row);
    const float* values = m_image.pixels.data() + static_cast<std::size_t>(row) * m_image.cols;
    for (int col = 0; col < m_image.cols; ++col) {
      const float g = (values[col] - low) * gain;
      line[col] = static_cast<uchar>(std::isfinite(g) ? std::clamp(g, 0.0f, 255.0f) : 0.0f);
    }
  }
}

std::optional<std::pair<int, int>> ImageViewWidget::pickPoint(const QPointF& p_widget) const {
  std::optional<std::pair<int, int>> best;
  double bestDistance = kPickRadius_px;
  for (std::size_t li = m_layers.size(); li-- > 0;) {  // topmost layer first
    const Layer& l = m_layers[li];
    if (!l.visible || !l.draggable || l.kind != LayerKind::Points) continue;
    for (std::size_t pi = 0; pi < l.points.size(); ++pi) {
      const QPointF d = QPointF(widgetPointForPixel(l.points[pi].uv_px)) - p_widget;
      const double distance = std::hypot(d.x(), d.y());
      if (distance <= bestDistance) {
        bestDistance = distance;
        best = std::make_pair(static_cast<int>(li), static_cast<int>(pi));
      }
    }
  }
  return best;
}

void ImageViewWidget::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.fillRect(rect(), QColor(12, 12, 14));
  if (m_image.empty()) {
    painter.setPen(QColor(150, 150, 150));
    painter.drawText(rect(), Qt::AlignCenter, m_placeholder.isEmpty() ? tr("No image") : m_placeholder);
    return;
  }
  const double s = scale();
  const QRectF target(imageCorner(), QSizeF(s * m_image.cols, s * m_image.rows));
  painter.setRenderHint(QPainter::SmoothPixmapTransform, s < 1.0);
  painter.drawImage(target, m_grey);

  painter.setRenderHint(QPainter::Antialiasing, true);
  const QPointF corner = imageCorner();
  auto toWidget = [&](const Eigen::Vector2d& uv) { return QPointF(corner.x() + s * (uv.x() + 0.5), corner.y() + s * (uv.y() + 0.5)); };
  // Images (masks, DRR blends) first, then outlines, then points: an outline is never hidden under an image layer.
  for (const LayerKind pass : {LayerKind::Image, LayerKind::Polylines, LayerKind::Points}) {
    for (const Layer& l : m_layers) {
      if (!l.visible || l.kind != pass) continue;
      switch (l.kind) {
        case LayerKind::Image:
          painter.setOpacity(l.opacity);
          painter.drawImage(target, l.image);
          painter.setOpacity(1.0);
          break;
        case LayerKind::Polylines: {
          painter.setOpacity(l.opacity);
          painter.setPen(QPen(l.color, 1.6));
          painter.setBrush(Qt::NoBrush);
          for (const auto& polyline : l.polylines) {
            if (polyline.size() < 2) continue;
            QPainterPath path(toWidget(polyline.front()));
            for (std::size_t i = 1; i < polyline.size(); ++i) path.lineTo(toWidget(polyline[i]));
            if (l.closed) path.closeSubpath();
            painter.drawPath(path);
          }
          painter.setOpacity(1.0);
          break;
        }
        case LayerKind::Points:
          for (const OverlayPoint& point : l.points) {
            const QPointF p = toWidget(point.uv_px);
            painter.setPen(QPen(QColor(0, 0, 0, 160), 3.0));
            painter.setBrush(Qt::NoBrush);
            painter.drawEllipse(p, kPointRadius_px, kPointRadius_px);
            painter.setPen(QPen(point.color, 1.6));
            painter.drawEllipse(p, kPointRadius_px, kPointRadius_px);
            painter.drawLine(p - QPointF(2, 0), p + QPointF(2, 0));
            painter.drawLine(p - QPointF(0, 2), p + QPointF(0, 2));
            if (!point.label.isEmpty()) {
              const QPointF at = p + QPointF(kPointRadius_px + 3, -kPointRadius_px);
              // A long name is elided so that it does not run over its neighbours' markers.
              const QString label = painter.fontMetrics().elidedText(point.label, Qt::ElideRight, kMaxLabelWidth_px);
              painter.setPen(QColor(0, 0, 0, 200));
              painter.drawText(at + QPointF(1, 1), label);
              painter.setPen(point.color);
              painter.drawText(at, label);
            }
          }
          break;
      }
    }
  }
  painter.setRenderHint(QPainter::Antialiasing, false);
  painter.setPen(QColor(230, 230, 230));
  const QFontMetrics metrics(font());
  if (!m_title.isEmpty()) painter.drawText(QPointF(8, 8 + metrics.ascent()), m_title);
  painter.setPen(QColor(170, 170, 170));
  painter.drawText(QPointF(8, height() - 8), tr("W %1  L %2  zoom %3×")
                                                 .arg(m_window, 0, 'g', 4)
                                                 .arg(m_level, 0, 'g', 4)
                                                 .arg(m_zoom, 0, 'f', 2));
}

void ImageViewWidget::wheelEvent(QWheelEvent* event) {
  zoomAbout(event->position(), event->angleDelta().y() / 120.0);
  event->accept();
}

void ImageViewWidget::zoomAbout(const QPointF& p_widget, double steps) {
  if (m_image.empty()) return;
  const Eigen::Vector2d uv = pixelForWidgetPoint(p_widget);
  setZoom(m_zoom * std::pow(1.2, steps));
  const double s = scale();
  const QPointF now(imageCorner().x() + s * (uv.x() + 0.5), imageCorner().y() + s * (uv.y() + 0.5));
  setPan(m_pan + (p_widget - now));
}

void ImageViewWidget::mousePressEvent(QMouseEvent* event) {
  m_pressPos = m_lastPos = event->position();
  m_drag = DragMode::None;
  if (m_image.empty()) return;
  if (event->button() == Qt::LeftButton && (event->modifiers() & Qt::ControlModifier)) {
    m_drag = DragMode::WindowLevel;
    m_pressWindow = m_window;
    m_pressLevel = m_level;
  } else if (event->button() == Qt::LeftButton) {
    if (const auto picked = pickPoint(event->position())) {
      m_drag = DragMode::PointPressed;
      m_dragPoint = *picked;
    } else {
      m_drag = DragMode::Click;
    }
  } else if (event->button() == Qt::MiddleButton || event->button() == Qt::RightButton) {
    m_drag = DragMode::Pan;
  }
  event->accept();
}

void ImageViewWidget::mouseMoveEvent(QMouseEvent* event) {
  const QPointF pos = event->position();
  if (!m_image.empty() && m_drag == DragMode::None) {
    const Eigen::Vector2d uv = pixelForWidgetPoint(pos);
    const int col = static_cast<int>(std::lround(uv.x()));
    const int row = static_cast<int>(std::lround(uv.y()));
    if (col >= 0 && row >= 0 && col < m_image.cols && row < m_image.rows) emit pixelHovered(uv, m_image.at(col, row));
    return;
  }
  const QPointF delta = pos - m_lastPos;
  m_lastPos = pos;
  switch (m_drag) {
    case DragMode::Click: {
      const QPointF moved = pos - m_pressPos;
      if (std::hypot(moved.x(), moved.y()) > kClickTolerance_px) {
        m_drag = DragMode::Pan;  // a left drag on the image pans, and is no longer a click
        setPan(m_pan + moved);
      }
      break;
    }
    case DragMode::Pan:
      setPan(m_pan + delta);
      break;
    case DragMode::WindowLevel: {
      const QPointF moved = pos - m_pressPos;
      const double unit = m_pressWindow / 256.0;
      setWindowLevel(m_pressWindow * std::exp(moved.x() / 200.0), m_pressLevel - moved.y() * unit);
      break;
    }
    case DragMode::PointPressed: {
      const QPointF moved = pos - m_pressPos;
      if (std::hypot(moved.x(), moved.y()) <= kClickTolerance_px) break;
      m_drag = DragMode::Point;
      [[fallthrough]];
    }
    case DragMode::Point: {
      Layer& l = m_layers[static_cast<std::size_t>(m_dragPoint.first)];
      const Eigen::Vector2d uv = pixelForWidgetPoint(pos);
      l.points[static_cast<std::size_t>(m_dragPoint.second)].uv_px = uv;
      update();
      emit pointDragged(l.name, m_dragPoint.second, uv);
      break;
    }
    case DragMode::None:
      break;
  }
}

void ImageViewWidget::mouseReleaseEvent(QMouseEvent* event) {
  const DragMode mode = m_drag;
  m_drag = DragMode::None;
  if (mode == DragMode::Click && event->button() == Qt::LeftButton) {
    const Eigen::Vector2d uv = pixelForWidgetPoint(event->position());
    const bool inside = uv.x() >= -0.5 && uv.y() >= -0.5 && uv.x() < m_image.cols - 0.5 && uv.y() < m_image.rows - 0.5;
    if (inside) emit pixelClicked(uv);
  } else if (mode == DragMode::PointPressed) {
    emit markerClicked(m_layers[static_cast<std::size_t>(m_dragPoint.first)].name, m_dragPoint.second);
  } else if (mode == DragMode::Point) {
    const QPointF moved = event->position() - m_pressPos;
    if (std::hypot(moved.x(), moved.y()) > 0.0) {
      Layer& l = m_layers[static_cast<std::size_t>(m_dragPoint.first)];
      emit pointDragged(l.name, m_dragPoint.second, pixelForWidgetPoint(event->position()));
    }
  }
  event->accept();
}

}  // namespace fct
