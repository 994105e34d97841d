// fluoroct register / drr as 3D Slicer CLI modules: --xml prints a well-formed module description that follows the
// Slicer Execution Model (checked with libxml2 against the rules of SlicerExecutionModel's ModuleDescriptionParser),
// every flag it names is one the command accepts, and a run with the arguments Slicer passes (a temporary NRRD CT,
// ITK .tfm transforms, --returnparameterfile) gives the same pose as the normal command.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <libxml/parser.h>
#include <libxml/tree.h>

#include <cmath>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "Base/JsonDocument.h"
#include "Base/TextFile.h"
#include "IO/Project/ItkTransformFile.h"
#include "IO/Project/PoseFile.h"
#include "Registration/RegistrationSchedule.h"
#include "SimulatedCliCase.h"

namespace {

namespace fs = std::filesystem;

/// A module description as libxml2 parsed it (null when the text is not well-formed XML).
struct XmlDocument {
  explicit XmlDocument(const std::string& text)
      : doc(xmlReadMemory(text.data(), static_cast<int>(text.size()), "module.xml", nullptr,
                          XML_PARSE_NONET | XML_PARSE_NOERROR | XML_PARSE_NOWARNING)) {}
  ~XmlDocument() { xmlFreeDoc(doc); }
  XmlDocument(const XmlDocument&) = delete;
  XmlDocument& operator=(const XmlDocument&) = delete;
  xmlDocPtr doc;
};

std::string nameOf(const xmlNode* node) { return reinterpret_cast<const char*>(node->name); }

std::vector<const xmlNode*> children(const xmlNode* node) {
  std::vector<const xmlNode*> elements;
  for (const xmlNode* child = node->children; child; child = child->next) {
    if (child->type == XML_ELEMENT_NODE) elements.push_back(child);
  }
  return elements;
}

/// The trimmed text of `node`.
std::string textOf(const xmlNode* node) {
  xmlChar* content = xmlNodeGetContent(node);
  std::string text = content ? reinterpret_cast<const char*>(content) : "";
  xmlFree(content);
  const auto first = text.find_first_not_of(" \t\r\n");
  const auto last = text.find_last_not_of(" \t\r\n");
  return first == std::string::npos ? "" : text.substr(first, last - first + 1);
}

/// One parameter of a description: its tag, attributes and child texts.
struct Parameter {
  std::string tag;
  std::map<std::string, std::string> attributes;
  std::multimap<std::string, std::string> fields;  ///< name, longflag, channel, element, default, ...
  std::string field(const std::string& key) const {
    const auto it = fields.find(key);
    return it == fields.end() ? "" : it->second;
  }
};

/// A parsed module description and the Execution Model rules it breaks (empty: none).
struct ModuleCheck {
  std::map<std::string, std::string> header;  ///< category, title, ...
  std::vector<Parameter> parameters;
  std::vector<std::string> problems;
};

/// Checks `text` the way SlicerExecutionModel's ModuleDescriptionParser reads it: <executable> outermost with its
/// header elements first, then <parameters> groups (each with a label) holding only known parameter tags; each
/// parameter with a valid, unique <name>, a valid <longflag> (letters, digits, underscores; no '-') or an <index>
/// but not both, only the attributes the parser accepts for its tag and their allowed values, <channel> input or
/// output on files, images and transforms, enumerations with elements and a default among them, and output scalars
/// without a flag (Slicer reads them from the return parameter file).
ModuleCheck checkModuleDescription(const std::string& text) {
  ModuleCheck check;
  const XmlDocument xml(text);
  if (!xml.doc) {
    check.problems.push_back("not well-formed XML");
    return check;
  }
  const xmlNode* root = xmlDocGetRootElement(xml.doc);
  if (!root || nameOf(root) != "executable") {
    check.problems.push_back("the outermost element is not <executable>");
    return check;
  }
  const std::set<std::string> headerTags{"category", "title",       "description", "version",         "documentation-url",
                                         "license",  "contributor", "acknowledgements", "index", "location"};
  const std::map<std::string, std::set<std::string>> allowedAttributes{
      {"integer", {"multiple"}},          {"double", {"multiple"}},   {"float", {"multiple"}},
      {"string", {"multiple"}},           {"boolean", {"hidden"}},    {"string-enumeration", {"hidden"}},
      {"integer-enumeration", {"hidden"}}, {"point", {"multiple", "coordinateSystem"}},
      {"file", {"multiple", "fileExtensions"}},
      {"image", {"multiple", "type", "fileExtensions", "hidden", "reference"}},
      {"transform", {"multiple", "type", "fileExtensions", "reference"}}};
  const std::set<std::string> parameterFields{"name",    "flag",    "longflag",    "label",   "description",
                                              "default", "channel", "index",       "element", "constraints"};
  const std::regex variable("[_A-Za-z][_A-Za-z0-9]*");
  std::set<std::string> names;
  bool inHeader = true;
  for (const xmlNode* element : children(root)) {
    const std::string tag = nameOf(element);
    if (tag != "parameters") {
      if (!inHeader || !headerTags.count(tag)) check.problems.push_back("<" + tag + "> where the header or <parameters> belongs");
      check.header[tag] = textOf(element);
      continue;
    }
    inHeader = false;
    bool labelled = false;
    for (const xmlNode* item : children(element)) {
      const std::string itemTag = nameOf(item);
      if (itemTag == "label" || itemTag == "description") {
        labelled = labelled || itemTag == "label";
        continue;
      }
      if (!allowedAttributes.count(itemTag)) {
        check.problems.push_back("<" + itemTag + "> is not a parameter tag FluoroCT's check knows");
        continue;
      }
      Parameter p;
      p.tag = itemTag;
      for (const xmlAttr* a = item->properties; a; a = a->next) {
        const std::string attribute = reinterpret_cast<const char*>(a->name);
        xmlChar* value = xmlGetProp(item, a->name);
        p.attributes[attribute] = reinterpret_cast<const char*>(value);
        xmlFree(value);
        if (!allowedAttributes.at(itemTag).count(attribute)) {
          check.problems.push_back("attribute '" + attribute + "' is not accepted on <" + itemTag + ">");
        }
      }
      for (const xmlNode* field : children(item)) {
        const std::string fieldTag = nameOf(field);
        if (!parameterFields.count(fieldTag)) check.problems.push_back("<" + fieldTag + "> inside <" + itemTag + ">");
        p.fields.emplace(fieldTag, textOf(field));
      }
      const std::string name = p.field("name");
      if (!std::regex_match(name, variable)) check.problems.push_back("parameter name '" + name + "' is not valid");
      if (!names.insert(name).second) check.problems.push_back("parameter name '" + name + "' is used twice");
      const std::string longflag = p.field("longflag");
      const std::string bareFlag = longflag.substr(std::min(longflag.find_first_not_of('-'), longflag.size()));
      if (!longflag.empty() && !std::regex_match(bareFlag, variable)) {
        check.problems.push_back("longflag '" + longflag + "' of '" + name + "' is not letters, digits and underscores");
      }
      if (!longflag.empty() && !p.field("index").empty()) check.problems.push_back("'" + name + "' has a flag and an index");
      const std::string channel = p.field("channel");
      const bool dataTag = p.tag == "file" || p.tag == "image" || p.tag == "transform";
      if (dataTag && channel != "input" && channel != "output") {
        check.problems.push_back("'" + name + "' has no <channel> input or output");
      }
      if (dataTag && longflag.empty() && p.field("index").empty()) check.problems.push_back("'" + name + "' has no flag");
      if (!dataTag && channel == "output" && !longflag.empty()) {
        check.problems.push_back("output scalar '" + name + "' has a flag; Slicer reads it from the return parameter file");
      }
      if (!dataTag && channel != "output" && longflag.empty()) check.problems.push_back("input '" + name + "' has no flag");
      if (p.tag == "transform" && p.attributes.count("type") &&
          !std::set<std::string>{"linear", "nonlinear", "bspline"}.count(p.attributes["type"])) {
        check.problems.push_back("transform type '" + p.attributes["type"] + "' of '" + name + "'");
      }
      if (p.tag == "image" && p.attributes.count("type") &&
          !std::set<std::string>{"any", "scalar", "label", "tensor", "diffusion-weighted", "vector"}.count(
              p.attributes["type"])) {
        check.problems.push_back("image type '" + p.attributes["type"] + "' of '" + name + "'");
      }
      if (p.tag.find("enumeration") != std::string::npos) {
        std::set<std::string> elements;
        for (auto [it, end] = p.fields.equal_range("element"); it != end; ++it) elements.insert(it->second);
        if (elements.empty()) check.problems.push_back("enumeration '" + name + "' has no <element>");
        if (!elements.count(p.field("default"))) check.problems.push_back("default of '" + name + "' is no element");
      }
      check.parameters.push_back(std::move(p));
    }
    if (!labelled) check.problems.push_back("a <parameters> group without a <label>");
  }
  if (check.parameters.empty()) check.problems.push_back("no parameters");
  for (const char* required : {"category", "title", "description"}) {
    if (check.header[required].empty()) check.problems.push_back(std::string("no <") + required + ">");
  }
  return check;
}

/// The parameter named `name`, or an empty one.
Parameter parameterNamed(const ModuleCheck& check, const std::string& name) {
  for (const Parameter& p : check.parameters) {
    if (p.field("name") == name) return p;
  }
  return {};
}

/// Every longflag of the description is an option of the command (its --help lists it).
void expectFlagsAccepted(const ModuleCheck& check, const std::string& command) {
  const auto help = fct::test::runCli(command + " --help");
  ASSERT_EQ(help.exitCode, 0) << help.err;
  for (const Parameter& p : check.parameters) {
    const std::string longflag = p.field("longflag");
    if (longflag.empty()) continue;
    EXPECT_NE(help.out.find("--" + longflag + " "), std::string::npos) << command << " has no --" << longflag;
  }
}

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

/// The CT of `dir`/ct.nrrd rewritten the way 3D Slicer writes a CLI module's temporary volume (its header comment,
/// LPS space, uncompressed), in a folder of its own.
fs::path slicerTemporaryVolume(const fs::path& dir) {
  auto text = fct::TextFile::read(dir / "ct.nrrd");
  EXPECT_TRUE(text.ok()) << text.error();
  const std::string& nrrd = text.value();
  const std::size_t dataStart = nrrd.find("\n\n") + 2;
  std::istringstream header(nrrd.substr(0, dataStart));
  std::string out = "NRRD0004\n# Complete NRRD file format specification at:\n# http://teem.sourceforge.net/nrrd/format.html\n";
  std::string line;
  std::getline(header, line);  // magic
  while (std::getline(header, line)) {
    if (!line.empty() && line[0] != '#') out += line + "\n";
  }
  out += "\n" + nrrd.substr(dataStart);
  fs::create_directories(dir / "SlicerTemp");
  const fs::path path = dir / "SlicerTemp" / "BCDEF_ct.nrrd";
  std::ofstream(path, std::ios::binary) << out;
  return path;
}

}  // namespace

TEST(SlicerModule, RegisterDescriptionFollowsTheExecutionModel) {
  const auto run = fct::test::runCli("register --xml");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const ModuleCheck check = checkModuleDescription(run.out);
  EXPECT_TRUE(check.problems.empty()) << joined(check.problems);
  EXPECT_EQ(check.header.at("category"), "Registration");
  EXPECT_EQ(check.header.at("title"), "FluoroCT 2D/3D registration");
  const Parameter ct = parameterNamed(check, "ct");
  EXPECT_EQ(ct.tag, "image");
  EXPECT_EQ(ct.field("channel"), "input");
  EXPECT_EQ(parameterNamed(check, "views").tag, "file");
  const Parameter init = parameterNamed(check, "init");
  EXPECT_EQ(init.tag, "transform");
  EXPECT_EQ(init.field("channel"), "input");
  EXPECT_EQ(init.attributes.at("fileExtensions"), ".tfm") << "Slicer is asked for ITK text transforms";
  const Parameter pose = parameterNamed(check, "registeredPose");
  EXPECT_EQ(pose.tag, "transform");
  EXPECT_EQ(pose.field("channel"), "output");
  EXPECT_EQ(pose.attributes.at("fileExtensions"), ".tfm");
  EXPECT_EQ(parameterNamed(check, "landmarks").tag, "file");
  const Parameter preset = parameterNamed(check, "preset");
  EXPECT_EQ(preset.tag, "string-enumeration");
  EXPECT_EQ(preset.fields.count("element"), fct::RegistrationSchedule::builtinNames().size());
  EXPECT_EQ(preset.field("default"), fct::RegistrationSchedule::kDefaultPreset);
  for (const char* output : {"finalSimilarity", "registrationSeconds", "drrCount"}) {
    EXPECT_EQ(parameterNamed(check, output).field("channel"), "output") << output;
  }
  expectFlagsAccepted(check, "register");
}

TEST(SlicerModule, DrrDescriptionFollowsTheExecutionModel) {
  const auto run = fct::test::runCli("drr --xml");
  ASSERT_EQ(run.exitCode, 0) << run.err;
  const ModuleCheck check = checkModuleDescription(run.out);
  EXPECT_TRUE(check.problems.empty()) << joined(check.problems);
  EXPECT_EQ(check.header.at("category"), "Registration");
  EXPECT_EQ(parameterNamed(check, "ct").tag, "image");
  EXPECT_EQ(parameterNamed(check, "pose").tag, "transform");
  EXPECT_EQ(parameterNamed(check, "drr").field("channel"), "output");
  expectFlagsAccepted(check, "drr");
}

TEST(SlicerModule, CheckFindsWhatTheExecutionModelParserRefuses) {
  EXPECT_EQ(checkModuleDescription("<executable><category>x</category>").problems,
            std::vector<std::string>{"not well-formed XML"});
  const ModuleCheck broken = checkModuleDescription(R"(<?xml version="1.0"?>
<executable><category>Registration</category><title>t</title><description>d</description>
  <parameters><label>In</label>
    <transform kind="linear"><name>init</name><longflag>init-pose</longflag></transform>
    <string-enumeration><name>preset</name><longflag>preset</longflag><default>slow</default><element>fast</element></string-enumeration>
    <double><name>result</name><longflag>result</longflag><channel>output</channel></double>
  </parameters>
</executable>)");
  const std::string problems = joined(broken.problems);
  EXPECT_NE(problems.find("attribute 'kind' is not accepted on <transform>"), std::string::npos) << problems;
  EXPECT_NE(problems.find("longflag 'init-pose'"), std::string::npos) << problems;
  EXPECT_NE(problems.find("'init' has no <channel>"), std::string::npos) << problems;
  EXPECT_NE(problems.find("default of 'preset' is no element"), std::string::npos) << problems;
  EXPECT_NE(problems.find("output scalar 'result' has a flag"), std::string::npos) << problems;
}

TEST(SlicerModule, SlicerStyleRunGivesTheSamePoseAsTheNormalCommand) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = fct::test::makeCase(dir);
  const Eigen::Isometry3d start = fct::test::perturbed(truth);
  ASSERT_TRUE(fct::PoseFile::write(start, dir / "init.json").ok());
  const auto normal = fct::test::runCli(fmt::format(
      "register --ct '{}' --views '{}' --init '{}' --preset fast --seed 2 --out '{}'", (dir / "ct.nrrd").string(),
      (dir / "sim" / "views.json").string(), (dir / "init.json").string(), (dir / "result.json").string()));
  ASSERT_EQ(normal.exitCode, 0) << normal.err;

  // As Slicer runs the module: the wrapper script, a temporary NRRD CT, the input transform node saved as .tfm, the
  // output transform and return parameter file in its temporary folder, every parameter by its longflag.
  const fs::path ct = slicerTemporaryVolume(dir);
  const fs::path temp = ct.parent_path();
  ASSERT_TRUE(fct::ItkTransformFile::write(start, temp / "BCDEF_init.tfm").ok());
  const fs::path wrapper = fct::test::cliPath().parent_path().parent_path() / "slicer-modules" / "FluoroCTRegister";
  ASSERT_TRUE(fs::exists(wrapper)) << wrapper;
  const std::string command = fmt::format(
      "'{}' --ct '{}' --views '{}' --init '{}' --preset fast --seed 2 --tfm '{}' --returnparameterfile '{}' > '{}' 2>&1",
      wrapper.string(), ct.string(), (dir / "sim" / "views.json").string(), (temp / "BCDEF_init.tfm").string(),
      (temp / "BCDEF_registeredPose.tfm").string(), (temp / "BCDEF_return.params").string(),
      (dir / "slicer-run.log").string());
  ASSERT_EQ(std::system(command.c_str()), 0) << command << "\n" << fct::TextFile::read(dir / "slicer-run.log").value();

  auto expected = fct::PoseFile::read(dir / "result.json");
  ASSERT_TRUE(expected.ok()) << expected.error();
  auto slicer = fct::ItkTransformFile::read(temp / "BCDEF_registeredPose.tfm");
  ASSERT_TRUE(slicer.ok()) << slicer.error();
  EXPECT_LT((slicer.value().translation() - expected.value().translation()).norm(), 1e-6);
  EXPECT_LT(Eigen::AngleAxisd(slicer.value().linear() * expected.value().linear().transpose()).angle(), 1e-8);
  EXPECT_LT((slicer.value().translation() - truth.translation()).norm(), 0.5) << "and it is the registered pose";

  auto params = fct::TextFile::read(temp / "BCDEF_return.params");
  ASSERT_TRUE(params.ok()) << params.error();
  auto json = fct::JsonDocument::parse(dir / "result.json");
  ASSERT_TRUE(json.ok()) << json.error();
  const std::regex line(R"(finalSimilarity = ([-0-9.e]+)\nregistrationSeconds = ([0-9.]+)\ndrrCount = ([0-9]+)\n)");
  std::smatch values;
  ASSERT_TRUE(std::regex_match(params.value(), values, line)) << params.value();
  EXPECT_NEAR(std::stod(values[1]), json.value()["stages"].back()["similarity"].get<double>(), 1e-6);
  EXPECT_GT(std::stod(values[2]), 0.0);
  EXPECT_EQ(std::stol(values[3]), json.value()["total_drrs"].get<long>());
}

TEST(SlicerModule, DrrWritesTheOneViewSlicerAsksForAtItsTransform) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = fct::test::makeCase(dir);
  ASSERT_TRUE(fct::ItkTransformFile::write(truth, dir / "pose.tfm").ok());
  const auto run = fct::test::runCli(fmt::format(
      "drr --ct '{}' --views '{}' --view lateral --pose '{}' --image '{}' --returnparameterfile '{}'",
      (dir / "ct.nrrd").string(), (dir / "sim" / "views.json").string(), (dir / "pose.tfm").string(),
      (dir / "drr.nrrd").string(), (dir / "return.params").string()));
  ASSERT_EQ(run.exitCode, 0) << run.err;
  EXPECT_TRUE(fs::exists(dir / "drr.nrrd"));
  EXPECT_FALSE(fs::exists(dir / "drr_lateral.nrrd")) << "--image is the exact file";
  auto params = fct::TextFile::read(dir / "return.params");
  ASSERT_TRUE(params.ok()) << params.error();
  EXPECT_EQ(params.value().rfind("renderSeconds = ", 0), 0u) << params.value();

  const auto allViews = fct::test::runCli(fmt::format("drr --ct '{}' --views '{}' --image '{}'", (dir / "ct.nrrd").string(),
                                                      (dir / "sim" / "views.json").string(),
                                                      (dir / "all.nrrd").string()));
  EXPECT_TRUE(fct::test::oneErrorLine(allViews)) << allViews.err;
  EXPECT_NE(allViews.err.find("choose one with --view"), std::string::npos) << allViews.err;
  EXPECT_FALSE(fs::exists(dir / "all.nrrd"));
}

TEST(SlicerModule, RefusesHdf5TransformsNamingTheTextFormat) {
  const fs::path dir = fct::test::scratchDir();
  const Eigen::Isometry3d truth = fct::test::makeCase(dir);
  std::ofstream(dir / "init.h5") << "not read";
  const std::string base = fmt::format("register --ct '{}' --views '{}'", (dir / "ct.nrrd").string(),
                                       (dir / "sim" / "views.json").string());
  const auto h5Input = fct::test::runCli(base + fmt::format(" --init '{}'", (dir / "init.h5").string()));
  EXPECT_TRUE(fct::test::oneErrorLine(h5Input)) << h5Input.err;
  EXPECT_NE(h5Input.err.find("--init: '" + (dir / "init.h5").string() + "' is an ITK HDF5 transform"), std::string::npos)
      << h5Input.err;
  EXPECT_NE(h5Input.err.find("(.tfm)"), std::string::npos) << h5Input.err;
  ASSERT_TRUE(fct::ItkTransformFile::write(truth, dir / "init.tfm").ok());
  const auto h5Output = fct::test::runCli(
      base + fmt::format(" --init '{}' --tfm '{}'", (dir / "init.tfm").string(), (dir / "out.h5").string()));
  EXPECT_TRUE(fct::test::oneErrorLine(h5Output)) << h5Output.err;
  EXPECT_NE(h5Output.err.find("--tfm:"), std::string::npos) << h5Output.err;
  EXPECT_FALSE(fs::exists(dir / "out.h5"));
}
