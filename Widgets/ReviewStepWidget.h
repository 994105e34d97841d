#pragma once
// ReviewStepWidget: the "Review" step, judging a registration by eye (like Fig. 2 of Knaan & Joskowicz 2003). Over each
// X-ray: the projected bone outlines (ContourOverlay) at the initial and at the final pose, each toggled, coloured and
// with an opacity; the DRR at the final pose blended over the X-ray or as a checkerboard, with a flicker toggle
// (a QTimer switching the DRR on and off). With a ground truth (simulated case) the sTRE, the mean bone-surface
// distance to the truth (BoneSurface), is shown for both poses. A chooser lists the session's result history (each run
// with its preset, time and verdict) and makes one the current result. Accept / Reject record the verdict in the
// document; the final pose exports as an ITK .tfm for 3D Slicer, as pose JSON or as a DICOM registration (REG), and the
// X-ray views as a PNG screenshot; "Send to Slicer" sends it live to 3D Slicer's OpenIGTLinkIF (host and port fields)
// off the GUI thread.

#include <Eigen/Core>
#include <QColor>
#include <QString>
#include <QWidget>

#include <array>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "Evaluation/ContourOverlay.h"
#include "Image/BoneSurface.h"
#include "Image/Volume.h"

class QCheckBox;
class QComboBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QSlider;
class QSpinBox;
class QTimer;
template <typename T>
class QFutureWatcher;

namespace fct {

class SliceViewWidget;
class StudioDocument;
class XrayViewWidget;

/// The Review step: contour overlays, DRR blend, sTRE, verdict and export.
class ReviewStepWidget : public QWidget {
  Q_OBJECT
 public:
  /// X-ray layers of this step.
  static inline const QString kInitialLayer = QStringLiteral("review-initial");
  static inline const QString kFinalLayer = QStringLiteral("review-final");
  static inline const QString kDrrLayer = QStringLiteral("review-drr");
  /// Flicker period (DRR on, then off), ms.
  static constexpr int kFlickerInterval_ms = 500;

  /// How the DRR at the final pose is shown over the X-ray.
  enum class DrrMode { Off, Blend, Checkerboard };

  /// A step reviewing `document`'s result.
  explicit ReviewStepWidget(StudioDocument* document, QWidget* parent = nullptr);

  /// The views this step draws on (X-ray view i shows document view i); slice views are not used.
  void attachViews(std::vector<XrayViewWidget*> xrayViews, std::array<SliceViewWidget*, 3> sliceViews);
  /// While active the step shows its layers (updated on document changes); inactive it hides them and stops flicker.
  void setActive(bool active);

  /// sTRE (mean bone-surface distance to the truth, mm) of the final pose; nullopt without a truth or a result.
  std::optional<double> finalSurfaceTre_mm() const { return m_finalTre_mm; }
  /// The message line, as shown.
  QString message() const;
  /// True while the DRR flickers.
  bool isFlickering() const;
  /// The result history chooser (one entry per result, the current one selected).
  QComboBox* historyChooser() const { return m_historyCombo; }

 public slots:
  /// Recomputes the contours, the DRR and the sTRE for the current document and redraws.
  void refresh();
  /// Shows or hides the outline at the initial / final pose.
  void setShowInitial(bool show);
  void setShowFinal(bool show);
  /// Outline colours.
  void setContourColours(const QColor& initial, const QColor& final);
  /// Opacity of both outlines, 0..1.
  void setContourOpacity(double opacity);
  /// DRR display mode and blend opacity (0..1).
  void setDrrMode(fct::ReviewStepWidget::DrrMode mode);
  void setDrrOpacity(double opacity);
  /// Starts or stops the DRR flicker.
  void setFlicker(bool on);
  /// Records accept / reject of the current result in the document.
  void acceptResult();
  void rejectResult();
  /// Writes the final pose: ITK transform for a path ending in .tfm, else pose JSON. False with the reason shown.
  bool exportPose(const QString& path);
  /// Writes the final pose as a DICOM Spatial Registration object (RegistrationDicomExport) referring to the CT and
  /// the DICOM X-rays; warnings (e.g. a generated Frame of Reference UID) are shown. False with the reason shown.
  bool exportDicomRegistration(const QString& path);
  /// Saves the X-ray views side by side as a PNG. False with the reason shown.
  bool saveScreenshot(const QString& path);
  /// Sets the OpenIGTLink server that "Send to Slicer" sends to (3D Slicer's OpenIGTLinkIF; default localhost:18944).
  void setSlicerAddress(const QString& host, int port);
  /// Sends the final pose to the OpenIGTLink server as a TRANSFORM "FluoroCT" in RAS, in a worker thread; the outcome
  /// is shown in the message line and signalled by slicerSendFinished. Refused without a result or a host.
  void sendToSlicer();

 signals:
  /// A "Send to Slicer" finished: sent, or not (the reason is in message()).
  void slicerSendFinished(bool sent);

 private:
  /// The (initial, final) poses to review as matrices: the result's, or the document's initial pose alone.
  using PosePair = std::pair<std::optional<Eigen::Matrix4d>, std::optional<Eigen::Matrix4d>>;
  PosePair reviewedPoses() const;
  /// Builds the bone outline projector and surface for the document's CT when it changed; false with a message.
  bool ensureOverlay();
  /// Redraws the contour layers from the cached contours.
  void drawContours();
  /// Redraws the DRR layer from the cached DRRs.
  void drawDrr();
  /// Shows the current result's verdict and refills the history chooser.
  void updateVerdict();
  void showMessage(const QString& text, bool error);

  StudioDocument* m_document;
  std::vector<XrayViewWidget*> m_xrayViews;
  bool m_active = false;

  std::shared_ptr<const Volume> m_overlayCt;  ///< CT of m_overlay and m_bone
  std::optional<ContourOverlay> m_overlay;
  std::optional<BoneSurface> m_bone;
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> m_initialContours;  ///< per view
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> m_finalContours;    ///< per view
  std::vector<QImage> m_drrGrey;                                             ///< per view, 8-bit grey DRR
  std::optional<double> m_finalTre_mm;
  PosePair m_shownPoses;  ///< the poses the cached contours and DRRs were made for

  bool m_showInitial = true;
  bool m_showFinal = true;
  QColor m_initialColour;
  QColor m_finalColour;
  double m_contourOpacity = 1.0;
  DrrMode m_drrMode = DrrMode::Off;
  double m_drrOpacity = 0.5;
  bool m_flickerShown = true;

  QComboBox* m_historyCombo;
  QCheckBox* m_initialCheck;
  QCheckBox* m_finalCheck;
  QPushButton* m_initialColourButton;
  QPushButton* m_finalColourButton;
  QSlider* m_contourOpacitySlider;
  QComboBox* m_drrModeCombo;
  QSlider* m_drrOpacitySlider;
  QCheckBox* m_flickerCheck;
  QTimer* m_flickerTimer;
  QLabel* m_treLabel;
  QLabel* m_verdictLabel;
  QLabel* m_message;
  QLineEdit* m_slicerHost;
  QSpinBox* m_slicerPort;
  QPushButton* m_sendToSlicerButton;
  QFutureWatcher<QString>* m_slicerSend;  ///< the send in flight; its result is the error text, empty when sent
};

}  // namespace fct
