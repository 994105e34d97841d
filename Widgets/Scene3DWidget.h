#pragma once
// Scene3DWidget: the 3D view of a StudioDocument, rendered by VTK through a vtkGenericOpenGLRenderWindow inside a
// QOpenGLWidget (Debian's VTK Qt module is Qt5-only). World frame = LPS mm. It shows the bone surface (flying edges
// at the bone threshold on a block-averaged copy of the CT) at the current pose (the registered pose if there is a
// result, else the initial pose, else identity), each C-arm view's X-ray source, its beam outline and its detector
// plane with the X-ray image textured in place. Mouse: left drag rotates, middle drag pans, wheel zooms.

#include <QOpenGLWidget>
#include <QSurfaceFormat>
#include <QString>

#include <Eigen/Geometry>
#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <vector>

class vtkActor;
class vtkGenericOpenGLRenderWindow;
class vtkGenericRenderWindowInteractor;
class vtkRenderer;
class vtkTextActor;
class QMouseEvent;
class QWheelEvent;

namespace fct {

class StudioDocument;

/// The 3D view.
class Scene3DWidget : public QOpenGLWidget {
  Q_OBJECT
 public:
  /// A 3D view of `document`, updated on its changes.
  explicit Scene3DWidget(StudioDocument* document, QWidget* parent = nullptr);
  ~Scene3DWidget() override;

  /// True when this platform can create the OpenGL 3.2 core context the view needs (false e.g. on Qt's offscreen
  /// platform, where a QOpenGLWidget must not even be shown).
  static bool openGlAvailable();
  /// The surface format the view asks for (OpenGL 3.2 core profile, as VTK's OpenGL2 backend needs).
  static QSurfaceFormat surfaceFormat();

  /// Bone threshold of the surface, HU (default 250).
  void setBoneThreshold_hu(double threshold_hu);
  /// Triangles of the bone surface shown (0 without a CT or bone).
  long boneTriangleCount() const { return m_boneTriangles; }
  /// Number of C-arm views drawn.
  int viewCount() const { return static_cast<int>(m_viewActors.size()); }
  /// What the bone's pose is, in words ("registered pose", "initial pose", "identity pose (no pose yet)").
  const QString& poseDescription() const { return m_poseDescription; }
  /// Points the camera at everything shown, from the patient's front-left, superior up.
  void resetCamera();

  QSize sizeHint() const override { return QSize(480, 360); }

 protected:
  void initializeGL() override;
  void paintGL() override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;

 private:
  /// Rebuilds the bone surface from the document's CT.
  void rebuildBone();
  /// Rebuilds the C-arm sources, beams and detector planes from the document's views.
  void rebuildViews();
  /// Places the bone at the current pose.
  void updatePose();
  /// Forwards a mouse event to VTK's interactor and repaints.
  void forwardMouse(QMouseEvent* event, unsigned long vtkEvent);
  /// Frees VTK's OpenGL objects of the widget's context before Qt destroys it.
  void releaseGraphics();

  StudioDocument* m_document;
  double m_boneThreshold_hu = 250.0;
  vtkNew<vtkGenericOpenGLRenderWindow> m_window;
  vtkNew<vtkGenericRenderWindowInteractor> m_interactor;
  vtkNew<vtkRenderer> m_renderer;
  vtkNew<vtkTextActor> m_caption;
  vtkSmartPointer<vtkActor> m_bone;
  Eigen::Affine3d m_T_ct_from_grid = Eigen::Affine3d::Identity();  ///< downsampled grid index -> CT LPS mm
  std::vector<vtkSmartPointer<vtkActor>> m_viewActors;
  long m_boneTriangles = 0;
  QString m_poseDescription;
  bool m_cameraPlaced = false;
};

}  // namespace fct
