#pragma once
// StudyCatalog: the built-in evaluation studies (the paper's experiments) as StudyDefinitions.
// - table2:   scenarios ideal / realistic / bad (registration CT at its own, 2.4 mm and 4.2 mm slice spacing) x CTs,
//             3 views, starts at 10 mm initial mean sTRE (the paper's Table 2).
// - capture:  initial mean sTRE bins of 10 mm from 0 to 60 mm, for NCC only, VLNC only and both (the paper's Fig. 3).
// - ablation: the full method, then each technique off in turn (dynamic ROIs, pyramid, NCC->VLNC, genetic search)
//             and CMA-ES in place of the genetic search (the paper's Table 1, measured); 10 mm starts. Every row
//             registers with the study's DRR method; with the transgraph method a "no-transgraph" row (exact Siddon
//             DRRs, no tables) is added; with another method the Transgraph is off in every row, said as a gap.
// - views:    1 to 5 views, 10 mm starts.
// Full studies use the default preset (RegistrationSchedule::kDefaultPreset) and an 800 x 600 detector at 0.4 mm; quick ones the "fast" preset, a 128 x 128
// detector at 2.4 mm, Transgraph tables at a 6 mm step and 2 trials per condition (a few minutes in all, for CI).

#include <string>
#include <string_view>
#include <vector>

#include "Base/Result.h"
#include "Evaluation/StudyDefinition.h"

namespace fct {

/// The built-in studies.
class StudyCatalog {
 public:
  /// Names of the built-in studies: table2, capture, ablation, views.
  static std::vector<std::string> names();
  /// The study `name` over the CTs labelled `ctLabels` (each condition is repeated per CT), full or quick, registering
  /// with DRR `method` (setup.method). Fails, listing the names, on an unknown study, and on an empty CT list.
  static Result<StudyDefinition> define(std::string_view name, bool quick, const std::vector<std::string>& ctLabels,
                                        DrrMethod method = DrrMethod::Siddon);
  /// Slice spacing (mm) of the registration CT in a scenario: ideal 0 (the original CT), realistic 2.4, bad 4.2.
  static double scenarioSliceSpacing_mm(std::string_view scenario);
  /// Whether a scenario's X-rays show foreign objects that are not in the CT (K-wires, screws): realistic and bad,
  /// as the paper's "some objects"; ideal has none.
  static bool scenarioHasForeignObjects(std::string_view scenario);
};

}  // namespace fct
