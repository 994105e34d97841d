#include "Widgets/XrayViewWidget.h"

namespace fct {

XrayViewWidget::XrayViewWidget(QWidget* parent) : ImageViewWidget(parent) { setPlaceholderText(tr("No X-ray")); }

void XrayViewWidget::setImage(const XrayImage& xray, bool keepView) {
  ImageViewWidget::setImage(FloatImage{xray.cols, xray.rows, xray.pixels}, keepView);
}

}  // namespace fct
