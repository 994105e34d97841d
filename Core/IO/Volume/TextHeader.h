#pragma once
// TextHeader: small parsing helpers for the text headers of NRRD and MetaImage files.

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "Base/Result.h"

namespace fct {

/// Helpers for "key: value" / "key = value" text headers.
class TextHeader {
 public:
  /// The text without leading and trailing white space.
  static std::string trim(std::string_view text);
  /// The text in lower case (ASCII).
  static std::string lower(std::string_view text);
  /// Exactly `count` finite numbers separated by spaces, commas or parentheses; fails naming `field` otherwise.
  static Result<std::vector<double>> numbers(std::string_view text, std::size_t count, std::string_view field);
  /// Exactly three whole numbers of voxels (i, j, k) that fit an int; fails naming `field` otherwise (a size of 0 or
  /// less passes here and is refused by VoxelCodec::voxelCount).
  static Result<std::array<int, 3>> sizes(std::string_view text, std::string_view field);
};

}  // namespace fct
