#pragma once
// SliceViewWidget: one CT slice, axial, coronal or sagittal in the CT's LPS frame, resampled on square pixels
// (trilinear), shown as an ImageViewWidget with a crosshair and CT point layers. Radiological layout as in 3D Slicer:
// axial: patient's left to the screen's right, posterior down; coronal: left to the right, inferior down;
// sagittal: posterior to the right, inferior down. The title gives the slice's position as its patient side and its
// LPS coordinate ("Sagittal  L 38.8 mm (LPS x 38.8)"). Mouse: wheel scrolls slices, ctrl + wheel zooms, middle or
// right drag pans, ctrl + left drag changes window/level, left click emits pointClicked with the CT point (LPS mm).

#include <Eigen/Core>
#include <QColor>
#include <QString>

#include <memory>
#include <vector>

#include "Image/Volume.h"
#include "Widgets/ImageViewWidget.h"

namespace fct {

/// The slice orientations.
enum class SliceOrientation { Axial, Coronal, Sagittal };

/// Window/level presets of the slice views.
enum class SliceWindowPreset { Bone, SoftTissue };

/// One CT point of an overlay layer.
struct SlicePoint {
  Eigen::Vector3d p_ct_mm = Eigen::Vector3d::Zero();  ///< CT LPS mm
  QString label;
  QColor color = Qt::yellow;
};

/// An interactive CT slice view.
class SliceViewWidget : public ImageViewWidget {
  Q_OBJECT
 public:
  /// An empty view of the given orientation.
  explicit SliceViewWidget(SliceOrientation orientation, QWidget* parent = nullptr);

  /// Shows `ct` (null: nothing); the crosshair moves to the CT centre and the bone window is applied.
  void setVolume(std::shared_ptr<const Volume> ct);
  /// The CT shown (may be null).
  const std::shared_ptr<const Volume>& volume() const { return m_ct; }
  /// The orientation.
  SliceOrientation orientation() const { return m_orientation; }
  /// Display name of an orientation ("Axial", "Coronal", "Sagittal").
  static QString orientationName(SliceOrientation orientation);
  /// A coordinate along LPS axis `lpsAxis` (0 x, 1 y, 2 z; mm) as the patient side it lies on, without a sign:
  /// "L 38.8" for x = 38.8 and "R 38.8" for x = -38.8 (likewise P/A for y, S/I for z).
  static QString sideCoordinate(int lpsAxis, double value_mm);
  /// A CT point in both forms every position of the Studio uses: "LPS (38.8, -12.0, 5.0) mm = L 38.8 A 12.0 S 5.0".
  static QString positionText(const Eigen::Vector3d& p_ct_mm);

  /// Moves the crosshair to a CT point (LPS mm); the slice follows it along the view's normal. Does not emit.
  void setCrosshair_ct_mm(const Eigen::Vector3d& p_ct_mm);
  /// The crosshair position, CT LPS mm.
  const Eigen::Vector3d& crosshair_ct_mm() const { return m_crosshair_ct_mm; }
  /// Moves the slice by `steps` slice spacings along the view's normal (the crosshair moves with it); emits
  /// crosshairMoved.
  void scrollSlices(double steps);
  /// Slice position along the view's normal, mm (LPS z for axial, y for coronal, -x for sagittal).
  double slicePosition_mm() const;
  /// Distance between neighbouring slices along the normal, mm.
  double sliceStep_mm() const { return m_sliceStep_mm; }

  /// Applies a window/level preset (bone: W 1800 L 400 HU; soft tissue: W 400 L 40 HU).
  void applyWindowPreset(SliceWindowPreset preset);

  /// Sets a layer of CT points; those within half a slice step of the slice are drawn. Draggable points move in
  /// the slice plane (ctPointDragged).
  void setCtPointLayer(const QString& name, std::vector<SlicePoint> points, bool draggable = false);

  /// Widget position of a CT point projected onto this view's slice plane (e.g. for QTest clicks).
  QPoint widgetPointForCtPoint(const Eigen::Vector3d& p_ct_mm) const;
  /// CT point (LPS mm) on the current slice under a widget position.
  Eigen::Vector3d ctPointForWidgetPoint(const QPointF& p_widget) const;

 signals:
  /// Left click on the slice at a CT point (LPS mm).
  void pointClicked(const Eigen::Vector3d& p_ct_mm);
  /// The user scrolled the slice; the crosshair is now at p_ct_mm (for linking the other views).
  void crosshairMoved(const Eigen::Vector3d& p_ct_mm);
  /// A draggable CT point was clicked without moving it (index into the layer's points).
  void ctPointClicked(const QString& layer, int index);
  /// A draggable CT point was moved to p_ct_mm (in the slice plane).
  void ctPointDragged(const QString& layer, int index, const Eigen::Vector3d& p_ct_mm);
  /// The CT point and value (HU) under the cursor.
  void ctPointHovered(const Eigen::Vector3d& p_ct_mm, float value_hu);

 protected:
  void wheelEvent(QWheelEvent* event) override;

 private:
  struct CtLayer {
    QString name;
    std::vector<SlicePoint> points;
    bool draggable = false;
    std::vector<int> shownIndex;  ///< index into points of each point drawn on the current slice
  };
  /// LPS point of slice pixel (col,row) on the current slice.
  Eigen::Vector3d ctPointForPixel(const Eigen::Vector2d& uv_px) const;
  /// Slice pixel (col,row) of an LPS point projected onto the plane.
  Eigen::Vector2d pixelForCtPoint(const Eigen::Vector3d& p_ct_mm) const;
  /// Resamples the slice at the crosshair's position and refreshes the layers.
  void updateSlice();
  /// Redraws the crosshair and the CT point layers for the current slice.
  void updateOverlays();

  SliceOrientation m_orientation;
  std::shared_ptr<const Volume> m_ct;
  Eigen::Vector3d m_right = Eigen::Vector3d::UnitX();   ///< LPS direction of increasing column
  Eigen::Vector3d m_down = Eigen::Vector3d::UnitY();    ///< LPS direction of increasing row
  Eigen::Vector3d m_normal = Eigen::Vector3d::UnitZ();  ///< m_right x m_down
  Eigen::Vector2d m_min_mm = Eigen::Vector2d::Zero();   ///< (right, down) coordinate of pixel (0,0)'s centre
  double m_pixel_mm = 1.0;                              ///< square pixel size of the slice image
  Eigen::Vector2i m_size_px = Eigen::Vector2i::Zero();  ///< slice image size
  double m_sliceStep_mm = 1.0;
  Eigen::Vector3d m_crosshair_ct_mm = Eigen::Vector3d::Zero();
  std::vector<CtLayer> m_ctLayers;
};

}  // namespace fct
