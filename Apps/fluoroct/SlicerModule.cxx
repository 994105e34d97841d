#include "SlicerModule.h"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "Base/TextFile.h"
#include "IO/Project/ItkTransformFile.h"
#include "IO/Project/PoseFile.h"
#include "Registration/RegistrationSchedule.h"

namespace fct::cli {

namespace {

/// The module header every FluoroCT module shares; `title` and `description` differ.
std::string moduleHeader(const std::string& title, const std::string& description) {
  return fmt::format(R"(<?xml version="1.0" encoding="utf-8"?>
<executable>
  <category>Registration</category>
  <title>{}</title>
  <description><![CDATA[{}]]></description>
  <version>0.1.0</version>
  <documentation-url>docs/slicer.md in the FluoroCT repository</documentation-url>
  <license>see the FluoroCT repository</license>
  <contributor>FluoroCT</contributor>
)",
                     title, description);
}

/// `<element>` lines of an enumeration.
std::string elements(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += fmt::format("      <element>{}</element>\n", name);
  return text;
}

/// Lower-case extension of `path`, e.g. ".tfm".
std::string lowerExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

/// The refusal for a transform file format FluoroCT does not read or write.
Status refuseTransformFormat(const std::string& path) {
  const std::string extension = lowerExtension(path);
  if (extension == ".h5" || extension == ".hdf5" || extension == ".mat") {
    return fail(fmt::format("'{}' is an ITK {} transform, which FluoroCT does not read or write; use an ITK text "
                            "transform (.tfm) — the FluoroCT Slicer modules ask Slicer for .tfm files",
                            path, extension == ".mat" ? "MATLAB" : "HDF5"));
  }
  return Ok{};
}

}  // namespace

std::string registerModuleXml() {
  return moduleHeader("FluoroCT 2D/3D registration",
                      "Registers a CT to a few calibrated X-ray images (Knaan & Joskowicz, MICCAI 2003): DRRs of the CT "
                      "are compared with the X-rays (NCC, then VLNC on dynamic ROIs) while a genetic search and a "
                      "downhill simplex move the bone pose. The output transform maps the CT into the C-arm world: "
                      "place the CT under it.") +
         fmt::format(R"(  <parameters>
    <label>Inputs</label>
    <description><![CDATA[The CT, the X-ray views and where the search starts.]]></description>
    <image type="scalar" fileExtensions=".nrrd">
      <name>ct</name>
      <longflag>ct</longflag>
      <label>CT volume</label>
      <channel>input</channel>
      <description><![CDATA[The pre-operative CT (HU).]]></description>
    </image>
    <file fileExtensions=".json">
      <name>views</name>
      <longflag>views</longflag>
      <label>View file</label>
      <channel>input</channel>
      <description><![CDATA[FluoroCT view file (JSON): each X-ray image with its calibrated camera.]]></description>
    </file>
    <transform type="linear" fileExtensions=".tfm">
      <name>init</name>
      <longflag>init</longflag>
      <label>Initial pose</label>
      <channel>input</channel>
      <description><![CDATA[Where the search starts: a transform placing the CT in the C-arm world. Give this or the landmark pairs.]]></description>
    </transform>
    <file fileExtensions=".json">
      <name>landmarks</name>
      <longflag>landmarks</longflag>
      <label>Landmark pairs</label>
      <channel>input</channel>
      <description><![CDATA[FluoroCT landmark pair file (JSON) naming a CT markups file (.mrk.json) and the matching X-ray clicks; the initial pose is estimated from it. Give this or the initial pose.]]></description>
    </file>
    <string-enumeration>
      <name>preset</name>
      <longflag>preset</longflag>
      <label>Preset</label>
      <description><![CDATA[Registration schedule: 'clinical' (the default), 'accurate' (every valid pixel in the last stage: a smaller error at about twice the time), 'paper' (the published three stages) or 'fast'.]]></description>
      <default>clinical</default>
{}    </string-enumeration>
    <integer>
      <name>seed</name>
      <longflag>seed</longflag>
      <label>Random seed</label>
      <description><![CDATA[Seed of the random searches; the same seed gives the same result.]]></description>
      <default>1</default>
    </integer>
  </parameters>
  <parameters>
    <label>Outputs</label>
    <description><![CDATA[The registered pose and the figures of the run.]]></description>
    <transform type="linear" fileExtensions=".tfm" reference="ct">
      <name>registeredPose</name>
      <longflag>tfm</longflag>
      <label>Registered pose</label>
      <channel>output</channel>
      <description><![CDATA[The registered bone pose: a transform placing the CT in the C-arm world.]]></description>
    </transform>
    <file fileExtensions=".json">
      <name>result</name>
      <longflag>out</longflag>
      <label>Result file</label>
      <channel>output</channel>
      <description><![CDATA[Optional FluoroCT result file (JSON) with the per-stage timings and similarities.]]></description>
    </file>
    <double>
      <name>finalSimilarity</name>
      <label>Final similarity</label>
      <channel>output</channel>
      <description><![CDATA[Similarity of the last stage at the registered pose (mean over the views).]]></description>
      <default>0</default>
    </double>
    <double>
      <name>registrationSeconds</name>
      <label>Time (s)</label>
      <channel>output</channel>
      <description><![CDATA[Wall time of the registration stages, seconds.]]></description>
      <default>0</default>
    </double>
    <integer>
      <name>drrCount</name>
      <label>DRRs rendered</label>
      <channel>output</channel>
      <description><![CDATA[DRRs rendered by all stages together.]]></description>
      <default>0</default>
    </integer>
  </parameters>
</executable>
)",
                     elements(RegistrationSchedule::builtinNames()));
}

std::string drrModuleXml() {
  return moduleHeader("FluoroCT DRR",
                      "Renders a digitally reconstructed radiograph of a CT for one calibrated X-ray view of a "
                      "FluoroCT view file, with the CT placed in the C-arm world by a transform.") +
         R"(  <parameters>
    <label>Inputs</label>
    <description><![CDATA[The CT, the view and the pose.]]></description>
    <image type="scalar" fileExtensions=".nrrd">
      <name>ct</name>
      <longflag>ct</longflag>
      <label>CT volume</label>
      <channel>input</channel>
      <description><![CDATA[The CT (HU).]]></description>
    </image>
    <file fileExtensions=".json">
      <name>views</name>
      <longflag>views</longflag>
      <label>View file</label>
      <channel>input</channel>
      <description><![CDATA[FluoroCT view file (JSON) with the calibrated cameras.]]></description>
    </file>
    <string>
      <name>view</name>
      <longflag>view</longflag>
      <label>View name</label>
      <description><![CDATA[The view to render; may be left empty when the view file has one view.]]></description>
    </string>
    <transform type="linear" fileExtensions=".tfm">
      <name>pose</name>
      <longflag>pose</longflag>
      <label>Pose</label>
      <channel>input</channel>
      <description><![CDATA[Transform placing the CT in the C-arm world (identity when none is selected).]]></description>
    </transform>
    <string-enumeration>
      <name>method</name>
      <longflag>method</longflag>
      <label>Method</label>
      <description><![CDATA[siddon (exact voxel traversal), raycast (trilinear sampling) or transgraph (precomputed ray table).]]></description>
      <default>siddon</default>
      <element>siddon</element>
      <element>raycast</element>
      <element>transgraph</element>
    </string-enumeration>
    <string-enumeration>
      <name>values</name>
      <longflag>values</longflag>
      <label>Values</label>
      <description><![CDATA[attenuation (line integral of mu from HU) or raw (line integral of the voxel value).]]></description>
      <default>attenuation</default>
      <element>attenuation</element>
      <element>raw</element>
    </string-enumeration>
    <integer>
      <name>level</name>
      <longflag>level</longflag>
      <label>Pyramid level</label>
      <description><![CDATA[Detector downsampled by 2^level per axis.]]></description>
      <default>0</default>
      <constraints>
        <minimum>0</minimum>
        <maximum>6</maximum>
        <step>1</step>
      </constraints>
    </integer>
  </parameters>
  <parameters>
    <label>Outputs</label>
    <description><![CDATA[The DRR.]]></description>
    <image type="scalar" fileExtensions=".nrrd">
      <name>drr</name>
      <longflag>image</longflag>
      <label>DRR</label>
      <channel>output</channel>
      <description><![CDATA[The DRR of the view (float, one slice, detector pixel spacing).]]></description>
    </image>
    <double>
      <name>renderSeconds</name>
      <label>Time (s)</label>
      <channel>output</channel>
      <description><![CDATA[Rendering time, seconds.]]></description>
      <default>0</default>
    </double>
  </parameters>
</executable>
)";
}

void addModuleXmlFlag(CLI::App* command, std::string xml) {
  command->add_flag_callback(
      "--xml",
      [xml = std::move(xml)] {
        fmt::print("{}", xml);
        throw CLI::Success();
      },
      "Print the 3D Slicer CLI module description (Slicer Execution Model XML) and exit");
}

Status writeReturnParameters(const std::string& path, const std::vector<std::pair<std::string, std::string>>& values) {
  std::string text;
  for (const auto& [name, value] : values) text += fmt::format("{} = {}\n", name, value);
  const Status written = TextFile::writeAtomically(path, text);
  if (!written) return fail("--returnparameterfile: " + written.error());
  return Ok{};
}

Result<Eigen::Isometry3d> readPoseOrTransform(const std::string& path) {
  if (Status refused = refuseTransformFormat(path); !refused) return fail(refused.error());
  const std::string extension = lowerExtension(path);
  if (extension == ".tfm" || extension == ".txt") return ItkTransformFile::read(path);
  return PoseFile::read(path);
}

Status checkWritableTransform(const std::string& path) { return refuseTransformFormat(path); }

}  // namespace fct::cli
