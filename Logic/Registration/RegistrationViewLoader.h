#pragma once
// RegistrationViewLoader: the views of a view file as registration takes them: the view file (ViewFile), each view's
// X-ray (XrayLoader), checked against its camera's detector, and the view's calibration-sphere shadows; a view that
// names a dewarp file has its X-ray resampled onto the ideal pixel grid (XrayDewarper) and its sphere shadows moved
// there, so that registration, the Studio's X-ray views and clicked landmarks all use ideal pixels. The one loader
// of the CLI (`register --views`) and the Studio (Data step).

#include <filesystem>
#include <vector>

#include "Base/Result.h"
#include "IO/Project/ViewFile.h"
#include "Registration/RegistrationView.h"

namespace fct {

/// Loads registration views.
class RegistrationViewLoader {
 public:
  /// Reads the view file and every view's image, in the file's order (flipped left-right when the view says
  /// mirror_columns, then dewarped when it names a dewarp file). Fails naming the file and the view on a view file
  /// error, a view without an image, an image that cannot be read, an image whose size is not the detector's, or an
  /// unreadable dewarp file or one calibrated for another image size.
  /// Warnings of the view file and of the images (the latter prefixed "view '<name>': ") are on the Result.
  static Result<std::vector<RegistrationView>> load(const std::filesystem::path& viewFile);

  /// One view's image (XrayLoader; flipped left-right when the view says mirror_columns, then dewarped when it names a
  /// dewarp file) with its camera and spheres. Fails naming the view when it has no image, the image cannot be read,
  /// its size is not the detector's or its dewarp file is unusable; the
  /// image's warnings are on the Result, prefixed "view '<name>': ".
  static Result<RegistrationView> loadView(const ViewSpec& spec);
  /// Frame `frame` (0-based) of the view's sequence, loaded as loadView() loads the image; fails as loadView() does,
  /// and naming the view when it has no sequence or the frame is out of range.
  static Result<RegistrationView> loadFrame(const ViewSpec& spec, int frame);
};

}  // namespace fct
