#pragma once
// XrayViewWidget: the view of one C-arm X-ray: an ImageViewWidget (window/level, zoom, pan, overlay layers, click and
// drag signals in detector pixels) that takes XrayImage frames.

#include "Image/XrayImage.h"
#include "Widgets/ImageViewWidget.h"

namespace fct {

/// An interactive view of one X-ray with overlays (all of ImageViewWidget's API, in the X-ray's pixels).
class XrayViewWidget : public ImageViewWidget {
  Q_OBJECT
 public:
  /// An empty X-ray view.
  explicit XrayViewWidget(QWidget* parent = nullptr);

  using ImageViewWidget::setImage;
  /// Shows an X-ray's pixels (MONOCHROME2 sense; see ImageViewWidget::setImage).
  void setImage(const XrayImage& xray, bool keepView = false);
};

}  // namespace fct
