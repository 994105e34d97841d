#pragma once
// ImageViewWidget: one 2D float image (an X-ray, a DRR, a CT slice) as grey levels with window/level, zoom and pan,
// and named overlay layers drawn over it in image pixels: points with labels (optionally draggable), polylines (contours) and ARGB images
// (ROI masks, DRR blends). Image layers are drawn first, then polylines, then points (each kind in creation order). Plain Qt painting. Mouse: wheel zooms about the cursor, middle or right drag pans,
// ctrl + left drag changes window (horizontal) and level (vertical), left click emits pixelClicked, left drag of a
// draggable point emits pointDragged, and a click on one emits markerClicked (a press that moves less than the click
// tolerance never moves a point). Pixel (col,row) = (0,0) is the centre of the top-left pixel.

#include <Eigen/Core>
#include <QColor>
#include <QImage>
#include <QPoint>
#include <QPointF>
#include <QString>
#include <QWidget>

#include <optional>
#include <vector>

#include "Image/FloatImage.h"

namespace fct {

/// One point of an overlay layer.
struct OverlayPoint {
  Eigen::Vector2d uv_px = Eigen::Vector2d::Zero();  ///< (col,row) in image pixels
  QString label;                                    ///< drawn beside the point (may be empty)
  QColor color = Qt::yellow;
};

/// An interactive view of one 2D image with overlays.
class ImageViewWidget : public QWidget {
  Q_OBJECT
 public:
  /// An empty view.
  explicit ImageViewWidget(QWidget* parent = nullptr);

  /// Shows `image` (any float values), keeps the layers, fits it to the view and picks a robust window/level
  /// (1st-99th percentile) unless keepView is set and the size is unchanged.
  void setImage(const FloatImage& image, bool keepView = false);
  /// Removes the image and every layer.
  void clear();
  /// True when an image is shown.
  bool hasImage() const { return !m_image.empty(); }
  /// Image size in pixels (0,0 when empty).
  QSize imageSize() const { return QSize(m_image.cols, m_image.rows); }
  /// The image shown.
  const FloatImage& image() const { return m_image; }

  /// Text shown when there is no image.
  void setPlaceholderText(const QString& text);
  /// A title drawn in the top-left corner (e.g. the view name).
  void setTitle(const QString& title);
  const QString& title() const { return m_title; }

  /// Window width and level (centre) in image units.
  void setWindowLevel(double window, double level);
  double window() const { return m_window; }
  double level() const { return m_level; }
  /// The robust window/level of the image (1st-99th percentile of its values).
  void resetWindowLevel();
  /// The q-quantile (0..1) of up to ~65k evenly spread finite values of `values` (0 when there are none).
  static double quantile(const std::vector<float>& values, double q);

  /// Zoom factor relative to "fit" (1 = the whole image fits the view).
  void setZoom(double zoom);
  double zoom() const { return m_zoom; }
  /// Pan offset of the image centre from the view centre, in widget pixels.
  void setPan(const QPointF& pan_widget_px);
  QPointF pan() const { return m_pan; }
  /// Fit the whole image (zoom 1, no pan).
  void resetView();

  /// Sets (creates or replaces) a point layer; draggable points can be moved with the left mouse button.
  void setPointLayer(const QString& name, std::vector<OverlayPoint> points, bool draggable = false);
  /// Sets a polyline layer: each polyline is a list of (col,row) pixel positions, in one colour, closed
  /// (last point joined to the first) unless `closed` is false.
  void setPolylineLayer(const QString& name, std::vector<std::vector<Eigen::Vector2d>> polylines_px, QColor color,
                        double opacity = 1.0, bool closed = true);
  /// Sets an image layer: an ARGB image of the shown image's size drawn over it with `opacity` (0..1). An image of another
  /// size is ignored (and the layer cleared), since it cannot be placed.
  void setImageLayer(const QString& name, QImage argb, double opacity = 1.0);
  /// Shows or hides a layer (kept while hidden).
  void setLayerVisible(const QString& name, bool visible);
  /// True when a layer of this name exists and is visible.
  bool isLayerVisible(const QString& name) const;
  /// True when a layer of this name exists.
  bool hasLayer(const QString& name) const;
  /// Removes a layer.
  void clearLayer(const QString& name);
  /// The points of a point layer (empty if none).
  std::vector<OverlayPoint> layerPoints(const QString& name) const;

  /// Widget position of image pixel (col,row) at the current zoom and pan (e.g. for QTest clicks).
  QPoint widgetPointForPixel(const Eigen::Vector2d& uv_px) const;
  /// Image pixel (col,row), continuous, under a widget position.
  Eigen::Vector2d pixelForWidgetPoint(const QPointF& p_widget) const;

  QSize sizeHint() const override { return QSize(480, 360); }

 signals:
  /// Left click (press and release without a drag) at an image pixel; only inside the image.
  void pixelClicked(const Eigen::Vector2d& uv_px);
  /// A draggable point was pressed and released without moving beyond the click tolerance (it is not moved).
  void markerClicked(const QString& layer, int index);
  /// A draggable point was dragged to uv_px (emitted while moving and on release), once the press moved beyond the
  /// click tolerance.
  void pointDragged(const QString& layer, int index, const Eigen::Vector2d& uv_px);
  /// The pixel under the cursor and its value (for a status line); emitted on mouse move inside the image.
  void pixelHovered(const Eigen::Vector2d& uv_px, float value);
  /// Window/level changed (by the user or a call).
  void windowLevelChanged(double window, double level);

 protected:
  void paintEvent(QPaintEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  /// Multiplies the zoom by 1.2^steps keeping the image point under p_widget in place.
  void zoomAbout(const QPointF& p_widget, double steps);

 private:
  enum class LayerKind { Points, Polylines, Image };
  struct Layer {
    QString name;
    LayerKind kind = LayerKind::Points;
    bool visible = true;
    bool draggable = false;
    std::vector<OverlayPoint> points;
    std::vector<std::vector<Eigen::Vector2d>> polylines;
    bool closed = true;
    QColor color;
    double opacity = 1.0;
    QImage image;
  };
  enum class DragMode { None, Click, Pan, WindowLevel, PointPressed, Point };

  Layer* findLayer(const QString& name);
  const Layer* findLayer(const QString& name) const;
  Layer& layer(const QString& name, LayerKind kind);
  /// Widget pixels per image pixel.
  double scale() const;
  /// Widget position of the top-left corner of the image (pixel (0,0)'s corner, i.e. uv = (-0.5,-0.5)).
  QPointF imageCorner() const;
  /// Rebuilds the 8-bit grey image from the float image and window/level.
  void updateGrey();
  /// The draggable point nearest to p_widget within a few pixels: (layer index, point index), or nullopt.
  std::optional<std::pair<int, int>> pickPoint(const QPointF& p_widget) const;

  FloatImage m_image;
  QImage m_grey;
  QString m_title;
  QString m_placeholder;
  double m_window = 1.0;
  double m_level = 0.5;
  double m_zoom = 1.0;
  QPointF m_pan{0.0, 0.0};
  std::vector<Layer> m_layers;  ///< in creation order (drawn first within its kind)

  DragMode m_drag = DragMode::None;
  QPointF m_pressPos;
  QPointF m_lastPos;
  double m_pressWindow = 1.0;
  double m_pressLevel = 0.5;
  std::pair<int, int> m_dragPoint{-1, -1};
};

}  // namespace fct
