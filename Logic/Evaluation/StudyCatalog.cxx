#include "Evaluation/StudyCatalog.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace fct {

namespace {

constexpr const char* kRealistic = "realistic";

/// The setup of every study: full (paper preset, clinical detector) or quick (fast preset, small detector).
StudySetup setupFor(bool quick) {
  StudySetup setup;
  if (quick) {
    setup.preset = "fast";
    setup.detector.cols = setup.detector.rows = 128;
    setup.detector.pixelSpacing_mm = 2.4;
    setup.detector.sourceToDetector_mm = 1000.0;
    setup.detector.sourceToIsocentre_mm = 700.0;
    setup.transgraphSpacing_mm = 6.0;
  }
  return setup;
}

StudyCondition baseCondition(const std::string& ct, const std::string& scenario, int trials) {
  StudyCondition c;
  c.ct = ct;
  c.scenario = scenario;
  c.sliceSpacing_mm = StudyCatalog::scenarioSliceSpacing_mm(scenario);
  c.trials = trials;
  return c;
}

void addTable2(StudyDefinition& d, const std::vector<std::string>& cts) {
  d.title = "Accuracy by CT slice spacing (the paper's Table 2): 3 views, starts at 10 mm mean sTRE";
  for (const std::string& ct : cts) {
    for (const char* scenario : {"ideal", "realistic", "bad"}) {
      StudyCondition c = baseCondition(ct, scenario, d.quick ? 2 : 20);
      c.name = fmt::format("{}/{}", ct, scenario);
      d.conditions.push_back(std::move(c));
    }
  }
}

void addCapture(StudyDefinition& d, const std::vector<std::string>& cts) {
  d.title = "Capture range by similarity measure (the paper's Fig. 3): initial mean sTRE bins, 3 views; with both "
            "measures also start rotations and the clinical setup alone (supine at the isocentre, no landmarks)";
  const int bins = d.quick ? 2 : 10;
  struct Measure {
    const char* name;
    StudyMeasures measures;
  };
  for (const std::string& ct : cts) {
    for (const Measure& m : {Measure{"ncc-only", StudyMeasures::NccOnly}, Measure{"vlnc-only", StudyMeasures::VlncOnly},
                             Measure{"both", StudyMeasures::Both}}) {
      for (int b = 0; b < bins; ++b) {
        StudyCondition c = baseCondition(ct, kRealistic, d.quick ? 2 : 10);
        c.variant = m.name;
        c.measures = m.measures;
        c.initialLow_mm = 10.0 * b;
        c.initialHigh_mm = 10.0 * (b + 1);
        c.name = fmt::format("{}/{}/{:02d}-{:02d}mm", ct, m.name, 10 * b, 10 * (b + 1));
        d.conditions.push_back(std::move(c));
      }
    }
    // Rotational capture: the truth rotated by 0-10, 10-20 and 20-30 deg about a random axis through the bone centre.
    for (int b = 0; b < (d.quick ? 1 : 3); ++b) {
      StudyCondition c = baseCondition(ct, kRealistic, d.quick ? 2 : 10);
      c.variant = "both";
      c.start = StudyStart::Rotation;
      c.rotationLow_deg = 10.0 * b;
      c.rotationHigh_deg = 10.0 * (b + 1);
      c.name = fmt::format("{}/both/rotation-{:02d}-{:02d}deg", ct, 10 * b, 10 * (b + 1));
      d.conditions.push_back(std::move(c));
    }
    StudyCondition setup = baseCondition(ct, kRealistic, d.quick ? 2 : 10);
    setup.variant = "both";
    setup.start = StudyStart::SupineSetup;
    setup.name = fmt::format("{}/both/supine-setup", ct);
    d.conditions.push_back(std::move(setup));
  }
}

void addAblation(StudyDefinition& d, const std::vector<std::string>& cts) {
  d.title = "Each technique off in turn (the paper's Table 1, measured): 3 views, starts at 10 mm mean sTRE";
  struct Variant {
    const char* name;
    RegistrationAblation ablation;
  };
  RegistrationAblation noRois, noPyramid, nccOnly, localOnly, cmaes;
  noRois.noDynamicRois = true;
  noPyramid.noPyramid = true;
  nccOnly.nccOnly = true;
  localOnly.localOnly = true;
  cmaes.cmaesForGenetic = true;
  std::vector<Variant> variants{{"full", {}},           {"no-rois", noRois},     {"no-pyramid", noPyramid},
                                {"ncc-only", nccOnly},  {"no-genetic", localOnly}, {"cmaes", cmaes}};
  const bool transgraph = d.setup.method == DrrMethod::Transgraph;
  RegistrationAblation noTransgraph;
  noTransgraph.noTransgraph = true;
  if (transgraph) variants.insert(variants.begin() + 1, Variant{"no-transgraph", noTransgraph});
  for (const std::string& ct : cts) {
    for (const Variant& v : variants) {
      StudyCondition c = baseCondition(ct, kRealistic, d.quick ? 2 : 20);
      c.variant = v.name;
      c.ablation = v.ablation;
      c.name = fmt::format("{}/{}", ct, v.name);
      d.conditions.push_back(std::move(c));
    }
  }
  if (!transgraph) {
    d.gaps.push_back(fmt::format("Transgraph off: no row. This run registers with the {} method, so every row already "
                                 "runs without the Transgraph; run the study with the transgraph DRR method to get a "
                                 "'no-transgraph' row (exact Siddon DRRs) beside the Transgraph rows.",
                                 DrrRendererFactory::methodName(d.setup.method)));
  }
}

void addViews(StudyDefinition& d, const std::vector<std::string>& cts) {
  d.title = "Accuracy by number of views: starts at 10 mm mean sTRE";
  const std::vector<int> counts = d.quick ? std::vector<int>{1, 2, 3} : std::vector<int>{1, 2, 3, 4, 5};
  for (const std::string& ct : cts) {
    for (int n : counts) {
      StudyCondition c = baseCondition(ct, kRealistic, d.quick ? 2 : 20);
      c.viewCount = n;
      c.variant = fmt::format("{}-views", n);
      c.name = fmt::format("{}/{}-views", ct, n);
      d.conditions.push_back(std::move(c));
    }
  }
}

}  // namespace

std::vector<std::string> StudyCatalog::names() { return {"table2", "capture", "ablation", "views"}; }

double StudyCatalog::scenarioSliceSpacing_mm(std::string_view scenario) {
  if (scenario == "realistic") return 2.4;
  if (scenario == "bad") return 4.2;
  return 0.0;
}

bool StudyCatalog::scenarioHasForeignObjects(std::string_view scenario) {
  return scenario == "realistic" || scenario == "bad";
}

Result<StudyDefinition> StudyCatalog::define(std::string_view name, bool quick, const std::vector<std::string>& ctLabels,
                                             DrrMethod method) {
  if (ctLabels.empty()) return fail(fmt::format("study '{}' needs at least one CT", name));
  StudyDefinition d;
  d.name = std::string(name);
  d.quick = quick;
  d.setup = setupFor(quick);
  d.setup.method = method;
  if (name == "table2") {
    addTable2(d, ctLabels);
  } else if (name == "capture") {
    addCapture(d, ctLabels);
  } else if (name == "ablation") {
    addAblation(d, ctLabels);
  } else if (name == "views") {
    addViews(d, ctLabels);
  } else {
    return fail(fmt::format("unknown study '{}'; the studies are: {}", name, fmt::join(names(), ", ")));
  }
  return d;
}

}  // namespace fct
