#include "Widgets/Scene3DWidget.h"

#include <QGuiApplication>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLExtraFunctions>
#include <QSurfaceFormat>
#include <QWheelEvent>

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGenericRenderWindowInteractor.h>
#include <vtkImageData.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkMapper.h>
#include <vtkMatrix4x4.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLState.h>
#include <vtkPlaneSource.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTexture.h>
#include <vtkUnsignedCharArray.h>

#include <algorithm>
#include <cmath>

#include "Widgets/StudioDocument.h"

namespace fct {

namespace {

constexpr int kMaxGridSide = 128;  ///< the bone surface is extracted on a block-averaged grid at most this large
constexpr std::size_t kActorsPerView = 3;  ///< detector, source, beam (in this order)

vtkSmartPointer<vtkMatrix4x4> vtkMatrix(const Eigen::Matrix4d& m) {
  auto matrix = vtkSmartPointer<vtkMatrix4x4>::New();
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) matrix->SetElement(r, c, m(r, c));
  return matrix;
}

/// The CT block-averaged by `block` voxels per axis, as VTK image data with unit spacing (grid index = point).
vtkSmartPointer<vtkImageData> blockAveraged(const Volume& ct, int block) {
  const Eigen::Vector3i dims = (ct.dims().array() + block - 1) / block;
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(dims.x(), dims.y(), dims.z());
  image->AllocateScalars(VTK_FLOAT, 1);
  auto* out = static_cast<float*>(image->GetScalarPointer());
  for (int k = 0; k < dims.z(); ++k) {
    for (int j = 0; j < dims.y(); ++j) {
      for (int i = 0; i < dims.x(); ++i) {
        double sum = 0.0;
        int count = 0;
        for (int kk = k * block; kk < std::min((k + 1) * block, ct.dims().z()); ++kk)
          for (int jj = j * block; jj < std::min((j + 1) * block, ct.dims().y()); ++jj)
            for (int ii = i * block; ii < std::min((i + 1) * block, ct.dims().x()); ++ii, ++count) sum += ct.at(ii, jj, kk);
        *out++ = static_cast<float>(sum / std::max(count, 1));
      }
    }
  }
  return image;
}

/// Grey bytes of an X-ray windowed to its 1st-99th percentile, rows flipped (VTK textures start at the bottom).
vtkSmartPointer<vtkImageData> textureImage(const XrayImage& xray) {
  std::vector<float> sample;
  const std::size_t step = std::max<std::size_t>(1, xray.pixels.size() / 65536);
  for (std::size_t i = 0; i < xray.pixels.size(); i += step) {
    if (std::isfinite(xray.pixels[i])) sample.push_back(xray.pixels[i]);
  }
  float low = 0.0f;
  float high = 1.0f;
  if (!sample.empty()) {
    std::sort(sample.begin(), sample.end());
    low = sample[sample.size() / 100];
    high = sample[sample.size() - 1 - sample.size() / 100];
  }
  const float gain = high > low ? 255.0f / (high - low) : 1.0f;
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(xray.cols, xray.rows, 1);
  image->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
  auto* out = static_cast<unsigned char*>(image->GetScalarPointer());
  for (int row = 0; row < xray.rows; ++row) {
    for (int col = 0; col < xray.cols; ++col) {
      const float g = (xray.at(col, xray.rows - 1 - row) - low) * gain;
      *out++ = static_cast<unsigned char>(std::isfinite(g) ? std::clamp(g, 0.0f, 255.0f) : 0.0f);
    }
  }
  return image;
}

vtkSmartPointer<vtkActor> actorOf(vtkPolyData* polyData) {
  auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
  mapper->SetInputData(polyData);
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  return actor;
}

}  // namespace

Scene3DWidget::Scene3DWidget(StudioDocument* document, QWidget* parent) : QOpenGLWidget(parent), m_document(document) {
  setFormat(surfaceFormat());
  m_window->AddRenderer(m_renderer);
  m_window->SetReadyForRendering(false);
  m_window->SetFrameBlitModeToNoBlit();  // paintGL copies the image into the widget's framebuffer
  m_renderer->SetBackground(0.10, 0.11, 0.14);
  m_renderer->SetBackground2(0.28, 0.30, 0.36);
  m_renderer->GradientBackgroundOn();
  m_caption->GetTextProperty()->SetFontSize(13);
  m_caption->GetTextProperty()->SetColor(0.85, 0.85, 0.85);
  m_caption->SetPosition(8, 8);
  m_renderer->AddViewProp(m_caption);

  // VTK asks whether the context is current and to make it current; answer with this widget's context.
  auto isCurrent = vtkSmartPointer<vtkCallbackCommand>::New();
  isCurrent->SetClientData(this);
  isCurrent->SetCallback([](vtkObject*, unsigned long, void* self, void* callData) {
    *static_cast<bool*>(callData) =
        QOpenGLContext::currentContext() == static_cast<Scene3DWidget*>(self)->context() &&
        QOpenGLContext::currentContext() != nullptr;
  });
  m_window->AddObserver(vtkCommand::WindowIsCurrentEvent, isCurrent);
  auto makeCurrent = vtkSmartPointer<vtkCallbackCommand>::New();
  makeCurrent->SetClientData(this);
  makeCurrent->SetCallback([](vtkObject*, unsigned long, void* self, void*) {
    // Only when not current: QOpenGLWidget::makeCurrent() also rebinds Qt's framebuffer behind VTK's state cache.
    auto* widget = static_cast<Scene3DWidget*>(self);
    if (QOpenGLContext::currentContext() != widget->context()) widget->makeCurrent();
  });
  m_window->AddObserver(vtkCommand::WindowMakeCurrentEvent, makeCurrent);
  auto supports = vtkSmartPointer<vtkCallbackCommand>::New();
  supports->SetCallback([](vtkObject*, unsigned long, void*, void* callData) { *static_cast<int*>(callData) = 1; });
  m_window->AddObserver(vtkCommand::WindowSupportsOpenGLEvent, supports);
  auto direct = vtkSmartPointer<vtkCallbackCommand>::New();
  direct->SetCallback([](vtkObject*, unsigned long, void*, void* callData) { *static_cast<int*>(callData) = 1; });
  m_window->AddObserver(vtkCommand::WindowIsDirectEvent, direct);

  m_interactor->SetRenderWindow(m_window);
  m_interactor->EnableRenderOff();  // rendering happens in paintGL only
  vtkNew<vtkInteractorStyleTrackballCamera> style;
  m_interactor->SetInteractorStyle(style);
  m_interactor->Initialize();

  connect(document, &StudioDocument::ctChanged, this, [this] {
    rebuildBone();
    m_cameraPlaced = false;
    update();
  });
  connect(document, &StudioDocument::viewsChanged, this, [this] {
    rebuildViews();
    m_cameraPlaced = false;
    update();
  });
  connect(document, &StudioDocument::initialPoseChanged, this, [this] {
    updatePose();
    update();
  });
  connect(document, &StudioDocument::resultChanged, this, [this] {
    updatePose();
    update();
  });
  rebuildBone();
  rebuildViews();
}

QSurfaceFormat Scene3DWidget::surfaceFormat() {
  QSurfaceFormat format;
  format.setRenderableType(QSurfaceFormat::OpenGL);
  format.setVersion(3, 2);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setRedBufferSize(8);
  format.setGreenBufferSize(8);
  format.setBlueBufferSize(8);
  format.setAlphaBufferSize(8);
  format.setDepthBufferSize(8);
  format.setStencilBufferSize(0);
  return format;
}

bool Scene3DWidget::openGlAvailable() {
  // Qt's offscreen platform may create contexts (with an X display around) but cannot show OpenGL widgets.
  if (QGuiApplication::platformName() == QStringLiteral("offscreen")) return false;
  QOpenGLContext probe;
  probe.setFormat(surfaceFormat());
  return probe.create() && probe.format().majorVersion() * 10 + probe.format().minorVersion() >= 32;
}

Scene3DWidget::~Scene3DWidget() {
  if (context()) disconnect(context(), nullptr, this, nullptr);  // the context outlives this part of the object
  makeCurrent();
  m_window->Finalize();
  doneCurrent();
}

void Scene3DWidget::setBoneThreshold_hu(double threshold_hu) {
  if (!std::isfinite(threshold_hu) || threshold_hu == m_boneThreshold_hu) return;
  m_boneThreshold_hu = threshold_hu;
  rebuildBone();
  update();
}

void Scene3DWidget::rebuildBone() {
  if (m_bone) m_renderer->RemoveActor(m_bone);
  m_bone = nullptr;
  m_boneTriangles = 0;
  const auto& ct = m_document->ct();
  if (ct && ct->voxelCount() > 0) {
    const int block = std::max(1, (ct->dims().maxCoeff() + kMaxGridSide - 1) / kMaxGridSide);
    vtkNew<vtkFlyingEdges3D> surface;
    surface->SetInputData(blockAveraged(*ct, block));
    surface->SetValue(0, m_boneThreshold_hu);
    surface->ComputeNormalsOn();
    surface->Update();
    auto polyData = vtkSmartPointer<vtkPolyData>::New();
    polyData->ShallowCopy(surface->GetOutput());
    m_boneTriangles = polyData->GetNumberOfPolys();
    if (m_boneTriangles > 0) {
      // Grid index g covers voxels block*g .. block*g + block-1: its centre is voxel block*g + (block-1)/2.
      Eigen::Affine3d T_ijk_from_grid = Eigen::Affine3d::Identity();
      T_ijk_from_grid.linear() *= block;
      T_ijk_from_grid.translation().setConstant(0.5 * (block - 1));
      m_T_ct_from_grid = ct->T_lps_from_ijk() * T_ijk_from_grid;
      m_bone = actorOf(polyData);
      m_bone->GetMapper()->ScalarVisibilityOff();  // one colour, not the iso-value through a lookup table
      m_bone->GetProperty()->SetColor(0.93, 0.86, 0.70);
      m_bone->GetProperty()->SetSpecular(0.2);
      m_renderer->AddActor(m_bone);
    }
  }
  updatePose();
}

void Scene3DWidget::rebuildViews() {
  for (const auto& actor : m_viewActors) m_renderer->RemoveActor(actor);
  m_viewActors.clear();
  for (const RegistrationView& view : m_document->views()) {
    const Camera& camera = view.camera;
    const int cols = camera.intrinsics().cols;
    const int rows = camera.intrinsics().rows;
    // Detector corners: pixel corners (-0.5, -0.5) .. (cols - 0.5, rows - 0.5).
    const Eigen::Vector3d topLeft = camera.detectorPoint_world_mm({-0.5, -0.5});
    const Eigen::Vector3d topRight = camera.detectorPoint_world_mm({cols - 0.5, -0.5});
    const Eigen::Vector3d bottomLeft = camera.detectorPoint_world_mm({-0.5, rows - 0.5});
    const Eigen::Vector3d bottomRight = camera.detectorPoint_world_mm({cols - 0.5, rows - 0.5});
    const Eigen::Vector3d source = camera.sourcePosition_world_mm();

    vtkNew<vtkPlaneSource> plane;  // texture (0,0) at Origin = bottom-left, s along Point1, t along Point2
    plane->SetOrigin(bottomLeft.x(), bottomLeft.y(), bottomLeft.z());
    plane->SetPoint1(bottomRight.x(), bottomRight.y(), bottomRight.z());
    plane->SetPoint2(topLeft.x(), topLeft.y(), topLeft.z());
    plane->Update();
    auto detector = actorOf(plane->GetOutput());
    if (view.xray.cols == cols && view.xray.rows == rows) {
      vtkNew<vtkTexture> texture;
      texture->SetInputData(textureImage(view.xray));
      texture->InterpolateOn();
      detector->SetTexture(texture);
    }
    detector->GetProperty()->SetLighting(false);
    m_viewActors.push_back(detector);

    vtkNew<vtkSphereSource> sphere;
    sphere->SetCenter(source.x(), source.y(), source.z());
    sphere->SetRadius(12.0);
    sphere->Update();
    auto sourceActor = actorOf(sphere->GetOutput());
    sourceActor->GetProperty()->SetColor(1.0, 0.8, 0.2);
    m_viewActors.push_back(sourceActor);

    vtkNew<vtkPoints> points;
    points->InsertNextPoint(source.data());
    for (const Eigen::Vector3d& corner : {topLeft, topRight, bottomRight, bottomLeft}) points->InsertNextPoint(corner.data());
    vtkNew<vtkCellArray> lines;
    for (vtkIdType c = 1; c <= 4; ++c) {
      const vtkIdType ray[2] = {0, c};
      lines->InsertNextCell(2, ray);
    }
    vtkNew<vtkPolyData> beam;
    beam->SetPoints(points);
    beam->SetLines(lines);
    auto beamActor = actorOf(beam);
    beamActor->GetProperty()->SetColor(1.0, 0.8, 0.2);
    beamActor->GetProperty()->SetOpacity(0.45);
    beamActor->GetProperty()->SetLighting(false);
    m_viewActors.push_back(beamActor);
  }
  for (const auto& actor : m_viewActors) m_renderer->AddActor(actor);
}

void Scene3DWidget::updatePose() {
  Eigen::Isometry3d T_world_from_ct = Eigen::Isometry3d::Identity();
  if (m_document->result()) {
    T_world_from_ct = m_document->result()->T_world_from_ct;
    m_poseDescription = m_document->result()->cancelled ? tr("best pose of the cancelled registration")
                                                        : tr("registered pose");
  } else if (m_document->initialPose()) {
    T_world_from_ct = *m_document->initialPose();
    m_poseDescription = tr("initial pose");
  } else {
    m_poseDescription = tr("identity pose (no pose yet)");
  }
  if (m_bone) m_bone->SetUserMatrix(vtkMatrix((T_world_from_ct * m_T_ct_from_grid).matrix()));
  QString caption;
  if (m_document->ct()) {
    caption = m_bone ? tr("Bone at the %1").arg(m_poseDescription)
                     : tr("No bone above %1 HU in the CT").arg(m_boneThreshold_hu);
  } else {
    caption = tr("No CT");
  }
  caption += tr("  ·  %1 C-arm view(s)").arg(m_document->views().size());
  m_caption->SetInput(caption.toUtf8().constData());
}

void Scene3DWidget::resetCamera() {
  vtkCamera* camera = m_renderer->GetActiveCamera();
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  camera->SetPosition(0.45, -1.0, 0.35);  // from the patient's front-left (LPS: -y anterior, +x left), a bit above
  camera->SetViewUp(0.0, 0.0, 1.0);       // superior up
  // Fit the bone and the detectors; the sources (a metre away) would make the bone a speck.
  double bounds[6] = {1e300, -1e300, 1e300, -1e300, 1e300, -1e300};
  const auto include = [&bounds](vtkActor* actor) {
    const double* b = actor->GetBounds();
    for (int a = 0; a < 3; ++a) {
      bounds[2 * a] = std::min(bounds[2 * a], b[2 * a]);
      bounds[2 * a + 1] = std::max(bounds[2 * a + 1], b[2 * a + 1]);
    }
  };
  if (m_bone) include(m_bone);
  for (std::size_t i = 0; i < m_viewActors.size(); i += kActorsPerView) include(m_viewActors[i]);  // detectors
  if (bounds[0] <= bounds[1]) {
    m_renderer->ResetCamera(bounds);
  } else {
    m_renderer->ResetCamera();
  }
  m_cameraPlaced = true;
}

void Scene3DWidget::initializeGL() {
  // Qt makes a new context when the view moves to another window: VTK's objects of the old one go with it, and the
  // new one is set up as the first was (otherwise the view stays black).
  connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, &Scene3DWidget::releaseGraphics, Qt::UniqueConnection);
  m_window->SetOwnContext(false);
  m_window->OpenGLInitContext();  // this widget's context is current and new
}

void Scene3DWidget::releaseGraphics() {
  makeCurrent();
  m_window->ReleaseGraphicsResources(m_window);
  doneCurrent();
}

void Scene3DWidget::paintGL() {
  if (!context() || !context()->isValid()) return;  // e.g. a platform without OpenGL (offscreen)
  if (!m_cameraPlaced) resetCamera();
  const qreal ratio = devicePixelRatioF();
  const int w = static_cast<int>(width() * ratio);
  const int h = static_cast<int>(height() * ratio);
  if (w <= 0 || h <= 0) return;  // collapsed: nothing to draw, and VTK's framebuffers keep their last size
  m_window->SetSize(w, h);
  m_interactor->SetSize(w, h);
  // VTK renders into its own framebuffers; then the image is copied into this widget's framebuffer.
  m_window->SetReadyForRendering(true);
  m_window->Render();
  m_window->SetReadyForRendering(false);
  makeCurrent();
  QOpenGLExtraFunctions* f = context()->extraFunctions();
  f->glBindFramebuffer(GL_DRAW_FRAMEBUFFER, defaultFramebufferObject());
  const GLenum colour = GL_COLOR_ATTACHMENT0;
  f->glDrawBuffers(1, &colour);
  const GLboolean scissor = f->glIsEnabled(GL_SCISSOR_TEST);
  if (scissor) {
    m_window->GetState()->vtkglDisable(GL_SCISSOR_TEST);
    f->glDisable(GL_SCISSOR_TEST);
  }
  const int* size = m_window->GetRenderFramebuffer()->GetLastSize();
  m_window->BlitDisplayFramebuffer(0, 0, 0, size[0], size[1], 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_LINEAR);
  // Opaque alpha, or Qt would blend the view with what is behind it.
  f->glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_TRUE);
  f->glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
  f->glViewport(0, 0, w, h);
  f->glClear(GL_COLOR_BUFFER_BIT);
  f->glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  if (scissor) {
    m_window->GetState()->vtkglEnable(GL_SCISSOR_TEST);
    f->glEnable(GL_SCISSOR_TEST);
  }
}

void Scene3DWidget::forwardMouse(QMouseEvent* event, unsigned long vtkEvent) {
  const qreal ratio = devicePixelRatioF();
  m_interactor->SetEventInformationFlipY(static_cast<int>(event->position().x() * ratio),
                                         static_cast<int>(event->position().y() * ratio),
                                         (event->modifiers() & Qt::ControlModifier) ? 1 : 0,
                                         (event->modifiers() & Qt::ShiftModifier) ? 1 : 0);
  m_interactor->InvokeEvent(vtkEvent, nullptr);
  update();
}

void Scene3DWidget::mousePressEvent(QMouseEvent* event) {
  switch (event->button()) {
    case Qt::LeftButton:
      forwardMouse(event, vtkCommand::LeftButtonPressEvent);
      break;
    case Qt::MiddleButton:
      forwardMouse(event, vtkCommand::MiddleButtonPressEvent);
      break;
    case Qt::RightButton:
      forwardMouse(event, vtkCommand::RightButtonPressEvent);
      break;
    default:
      break;
  }
}

void Scene3DWidget::mouseMoveEvent(QMouseEvent* event) {
  if (event->buttons() != Qt::NoButton) forwardMouse(event, vtkCommand::MouseMoveEvent);
}

void Scene3DWidget::mouseReleaseEvent(QMouseEvent* event) {
  switch (event->button()) {
    case Qt::LeftButton:
      forwardMouse(event, vtkCommand::LeftButtonReleaseEvent);
      break;
    case Qt::MiddleButton:
      forwardMouse(event, vtkCommand::MiddleButtonReleaseEvent);
      break;
    case Qt::RightButton:
      forwardMouse(event, vtkCommand::RightButtonReleaseEvent);
      break;
    default:
      break;
  }
}

void Scene3DWidget::wheelEvent(QWheelEvent* event) {
  const qreal ratio = devicePixelRatioF();
  m_interactor->SetEventInformationFlipY(static_cast<int>(event->position().x() * ratio),
                                         static_cast<int>(event->position().y() * ratio), 0, 0);
  m_interactor->InvokeEvent(event->angleDelta().y() > 0 ? vtkCommand::MouseWheelForwardEvent
                                                         : vtkCommand::MouseWheelBackwardEvent,
                            nullptr);
  update();
  event->accept();
}

}  // namespace fct
