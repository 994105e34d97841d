#pragma once
// Shared plumbing of the fluoroct command-line tool: how commands register and how errors are reported.

#include <CLI/CLI.hpp>

#include <atomic>
#include <filesystem>
#include <optional>
#include <functional>
#include <string>
#include <vector>

namespace fct::cli {

/// Exit status of every failed command.
constexpr int kExitError = 2;
/// Exit status of `register --igtl` when the registration succeeded and its result was written, but the pose could
/// not be sent over OpenIGTLink.
constexpr int kExitSendFailed = 3;

/// The action a parsed subcommand runs; returns the process exit status.
using CommandAction = std::function<int()>;

/// Prints "error: <message>" as one line on stderr and returns kExitError.
int reportError(const std::string& message);

/// Prints each warning (e.g. of a Result) as one line "warning: <text>" on stderr.
void printWarnings(const std::vector<std::string>& warnings);

/// Parses a detector size "COLSxROWS" (e.g. "800x600", x or X) into pixels; false on anything else or a size below 1.
bool parseDetectorSize(const std::string& text, int& cols, int& rows);

/// The Transgraph cache folder of a --transgraph-cache value: nullopt for "none" (no cache), else the folder (empty =
/// the default folder).
std::optional<std::filesystem::path> transgraphCacheFolder(const std::string& option);

/// Option check: the value must be a finite number > 0; the message names the value given.
CLI::Validator positiveNumber();

/// Adds --cut-face-margin-mm (register, track) bound to `margin_mm`: a finite number of mm up to
/// RegistrationCaseOptions::kMaxCutFaceMargin_mm, negative for off, shown with its default.
void addCutFaceMarginOption(CLI::App& command, double& margin_mm);

/// Adds --bone-contrast (register, track) bound to `contrast`: a finite number above 0 and up to
/// DrrValueOptions::kMaxBoneContrast, shown with its default.
void addBoneContrastOption(CLI::App& command, double& contrast);

/// While alive, Ctrl-C (SIGINT) sets cancelFlag() instead of ending the process, so a long Logic operation can stop
/// cleanly; the previous handler is restored when the guard goes, on every path out of its scope. Create one at a time.
class InterruptGuard {
 public:
  /// Clears the flag and installs the handler.
  InterruptGuard();
  /// Restores the handler that was installed before.
  ~InterruptGuard();
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

  /// The flag Ctrl-C sets (for ProgressMonitor and the cancel arguments of Logic).
  static const std::atomic<bool>* cancelFlag();

 private:
  void (*m_previous)(int);
};

// Each command file provides a register function: it adds its subcommand to `app` and, when the subcommand is
// chosen, stores its action in `action` (run after parsing).

/// `fluoroct info`: describes a CT or an X-ray (text or --json).
void registerInfoCommand(CLI::App& app, CommandAction& action);
/// `fluoroct pose`: writes a pose moved by a given or random offset about the bone centre.
void registerPoseCommand(CLI::App& app, CommandAction& action);
/// `fluoroct phantom`: writes the built-in procedural CT phantom to a NRRD or MetaImage file.
void registerPhantomCommand(CLI::App& app, CommandAction& action);
/// `fluoroct drr`: renders DRRs of a CT for the views of a view file.
void registerDrrCommand(CLI::App& app, CommandAction& action);
/// `fluoroct views`: writes a view file of standard C-arm views around a CT's centre.
void registerViewsCommand(CLI::App& app, CommandAction& action);
/// `fluoroct simulate`: writes simulated X-ray images of a CT at a pose, with a view file and the true pose.
void registerSimulateCommand(CLI::App& app, CommandAction& action);
/// `fluoroct register`: registers a CT to the X-ray views of a view file and writes the result JSON.
void registerRegisterCommand(CLI::App& app, CommandAction& action);
/// `fluoroct track`: follows the bone through a fluoroscopy sequence and writes the per-frame poses.
void registerTrackCommand(CLI::App& app, CommandAction& action);
/// `fluoroct tre`: prints the pose error (sTRE, mTRE, rotation, translation) of an estimate against the truth.
void registerTreCommand(CLI::App& app, CommandAction& action);
/// `fluoroct evaluate`: runs an evaluation study and writes trials.csv, report.md and charts.
void registerEvaluateCommand(CLI::App& app, CommandAction& action);
/// `fluoroct dewarp-calibrate`: fits an image-intensifier dewarp from a grid plate X-ray and writes a dewarp file.
void registerDewarpCalibrateCommand(CLI::App& app, CommandAction& action);


}  // namespace fct::cli
