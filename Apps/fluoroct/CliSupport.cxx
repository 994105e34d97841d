#include "CliSupport.h"

#include <fmt/core.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <utility>

#include "Registration/RegistrationCase.h"

namespace fct::cli {

namespace {

std::atomic<bool> g_interrupted{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the SIGINT handler stores to the flag");

extern "C" void onInterrupt(int) { g_interrupted.store(true); }

}  // namespace

int reportError(const std::string& message) {
  std::string oneLine = message;
  for (char& c : oneLine) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  fmt::print(stderr, "error: {}\n", oneLine);
  return kExitError;
}

void printWarnings(const std::vector<std::string>& warnings) {
  for (const std::string& warning : warnings) fmt::print(stderr, "warning: {}\n", warning);
}

bool parseDetectorSize(const std::string& text, int& cols, int& rows) {
  char separator = 0, trailing = 0;
  return std::sscanf(text.c_str(), "%d%c%d%c", &cols, &separator, &rows, &trailing) == 3 &&
         (separator == 'x' || separator == 'X') && cols >= 1 && rows >= 1;
}

std::optional<std::filesystem::path> transgraphCacheFolder(const std::string& option) {
  if (option == "none") return std::nullopt;
  return std::filesystem::path(option);
}

namespace {

/// Option check: the value must be a finite number that `accepts` takes; else "must be REQUIREMENT, got 'TEXT'".
CLI::Validator finiteNumber(bool (*accepts)(double), std::string requirement, std::string name) {
  return CLI::Validator(
      [accepts, requirement](std::string& text) -> std::string {
        double value = 0.0;
        if (CLI::detail::lexical_cast(text, value) && std::isfinite(value) && accepts(value)) return {};
        return fmt::format("must be {}, got '{}'", requirement, text);
      },
      std::move(name));
}

}  // namespace

CLI::Validator positiveNumber() {
  return finiteNumber([](double value) { return value > 0.0; }, "a positive number", "POSITIVE");
}

void addCutFaceMarginOption(CLI::App& command, double& margin_mm) {
  command
      .add_option("--cut-face-margin-mm", margin_mm,
                  "Leave out the pixels whose rays, at the pose a search starts from, cross the patient beyond the "
                  "CT's first or last slice or pass within this many mm of those cut faces (the X-ray shows anatomy "
                  "there that the CT lacks); negative = off")
      ->check(finiteNumber([](double value) { return value <= RegistrationCaseOptions::kMaxCutFaceMargin_mm; },
                           fmt::format("a number of mm up to {:g} (negative: off)",
                                       RegistrationCaseOptions::kMaxCutFaceMargin_mm),
                           "MM"))
      ->capture_default_str();
}

void addBoneContrastOption(CLI::App& command, double& contrast) {
  command
      .add_option("--bone-contrast", contrast,
                  "Scale the attenuation the DRRs give CT values above 100 HU (bone) by this factor: how much more "
                  "the X-ray's beam sees of bone than the CT's did. The default suits an 80 kVp fluoroscope and a "
                  "120 kVp CT, about 1.3 a 100 kVp one; 1 = the CT's own contrast (docs/registration.md, \"Bone "
                  "contrast\")")
      ->check(finiteNumber(DrrValueOptions::acceptsBoneContrast,
                           fmt::format("a number above 0 and up to {:g}", DrrValueOptions::kMaxBoneContrast),
                           "FACTOR"))
      ->capture_default_str();
}

InterruptGuard::InterruptGuard() {
  g_interrupted = false;
  m_previous = std::signal(SIGINT, onInterrupt);
}

InterruptGuard::~InterruptGuard() {
  if (m_previous != SIG_ERR) std::signal(SIGINT, m_previous);
}

const std::atomic<bool>* InterruptGuard::cancelFlag() { return &g_interrupted; }

}  // namespace fct::cli
