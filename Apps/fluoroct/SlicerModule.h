#pragma once
// SlicerModule: what makes `fluoroct register` and `fluoroct drr` 3D Slicer CLI modules (Slicer Execution Model):
// the module description printed by --xml, the --returnparameterfile of scalar results, and poses read from the
// ITK transform files Slicer passes (resampling convention, LPS; see IO/Project/ItkTransformFile.h).
// Slicer finds the modules through the wrapper scripts in build/slicer-modules/ (docs/slicer.md).

#include <CLI/CLI.hpp>
#include <Eigen/Geometry>

#include <string>
#include <utility>
#include <vector>

#include "Base/Result.h"

namespace fct::cli {

/// The Execution Model description of `fluoroct register` (category Registration).
std::string registerModuleXml();
/// The Execution Model description of `fluoroct drr` (category Registration).
std::string drrModuleXml();

/// Adds --xml to `command`: prints `xml` on stdout and ends the program with status 0 before other options are
/// checked (Slicer runs the module with --xml alone to discover it).
void addModuleXmlFlag(CLI::App* command, std::string xml);

/// Writes the scalar results Slicer reads back after the run, one "name = value" line each, atomically; fails
/// naming the file if it cannot be written.
Status writeReturnParameters(const std::string& path, const std::vector<std::pair<std::string, std::string>>& values);

/// Reads a pose T_world_from_ct (LPS mm) from a pose JSON file or an ITK transform file (.tfm, .txt) as Slicer
/// writes it; an HDF5 transform (.h5, .hdf5) or MATLAB one (.mat) is refused with what to choose instead.
Result<Eigen::Isometry3d> readPoseOrTransform(const std::string& path);

/// Fails with what to choose instead when `path` names a transform format FluoroCT cannot write (.h5, .hdf5, .mat).
Status checkWritableTransform(const std::string& path);

}  // namespace fct::cli
