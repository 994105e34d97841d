#pragma once
// The coarse known-truth case of the registration tests that only need a quick image: the small phantom on a 128x128
// detector at 2.4 mm (RegistrationTestCase.h), or on a detector of the test's own, with the registration case made
// from it.

#include <gtest/gtest.h>

#include <cstddef>
#include <utility>

#include "RegistrationTestCase.h"

namespace fct::test {

/// A simulated case and the registration case made from its CT and views.
struct PreparedCase {
  KnownTruthCase simulated;
  RegistrationCase registrationCase;
};

/// The small phantom seen by the first `viewCount` standard views on the detector of `options`.
inline PreparedCase preparePhantom(const KnownTruthOptions& options, std::size_t viewCount) {
  auto simulated = simulateCase(smallPhantom(), options);
  EXPECT_TRUE(simulated.ok()) << simulated.error();
  simulated.value().views.resize(viewCount);
  auto registrationCase = RegistrationCase::create(simulated.value().ct, simulated.value().views, {});
  EXPECT_TRUE(registrationCase.ok()) << registrationCase.error();
  return PreparedCase{std::move(simulated).value(), std::move(registrationCase).value()};
}

/// The small phantom seen by the first `viewCount` standard views on a coarse 128x128 detector at 2.4 mm.
inline PreparedCase prepareCoarsePhantom(std::size_t viewCount) {
  KnownTruthOptions options;
  options.cols = options.rows = 128;
  options.pixelSpacing_mm = 2.4;
  return preparePhantom(options, viewCount);
}

}  // namespace fct::test
