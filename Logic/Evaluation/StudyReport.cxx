#include "Evaluation/StudyReport.h"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <map>
#include <thread>

#include "Base/TextFile.h"
#include "Drr/DrrRendererFactory.h"
#include "Evaluation/LineChart.h"
#include "Evaluation/PoseErrorMetrics.h"
#include "Evaluation/SuccessRateBound.h"

namespace fct {

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

std::string mm(double value) { return std::isnan(value) ? "–" : fmt::format("{:.2f}", value); }
/// "95 % (19/20, ≥ 78 %)": the rate, the counts and the one-sided 95 % Clopper-Pearson lower bound.
std::string percent(const ConditionStats& s) {
  if (s.trials == 0) return "–";
  return fmt::format("{:.0f} % ({}/{}, ≥ {:.0f} %)", 100.0 * s.successRate, s.successes, s.trials,
                     100.0 * SuccessRateBound::lower(s.successes, s.trials));
}

/// The paper's Table 2 mean (max) sTRE on its simulated clinical pelvis for a scenario, "—" where it has none.
std::string paperTable2(const std::string& scenario) {
  if (scenario == "realistic") return "0.3 (0.7)";
  if (scenario == "bad") return "0.5 (0.7)";
  return "—";
}

std::vector<TrialRecord> recordsOf(const StudyDefinition& study, const StudyCondition& c,
                                   const std::vector<TrialRecord>& records) {
  std::vector<TrialRecord> out;
  for (const TrialRecord& r : records) {
    if (r.study == study.name && r.condition == c.name) out.push_back(r);
  }
  return out;
}

/// Conditions grouped by (CT, variant), in definition order: the series of capture and views charts.
std::vector<std::pair<std::string, std::vector<const StudyCondition*>>> groups(const StudyDefinition& study,
                                                                              bool byVariant,
                                                                              bool distanceStartsOnly = false) {
  std::vector<std::pair<std::string, std::vector<const StudyCondition*>>> out;
  for (const StudyCondition& c : study.conditions) {
    if (distanceStartsOnly && c.start != StudyStart::SurfaceDistance) continue;
    const std::string key = byVariant ? fmt::format("{} {}", c.ct, c.variant) : c.ct;
    auto found = std::find_if(out.begin(), out.end(), [&](const auto& g) { return g.first == key; });
    if (found == out.end()) {
      out.emplace_back(key, std::vector<const StudyCondition*>{});
      found = out.end() - 1;
    }
    found->second.push_back(&c);
  }
  return out;
}

std::string header(const StudyDefinition& study, const std::vector<std::string>& notes) {
  std::string text = fmt::format("# Study `{}`{}\n\n{}\n\n", study.name, study.quick ? " (quick)" : "", study.title);
  text += fmt::format("- written {:%Y-%m-%d %H:%M} UTC on a machine with {} hardware threads\n",
                      fmt::gmtime(std::time(nullptr)), std::thread::hardware_concurrency());
  const StandardViewOptions& d = study.setup.detector;
  text += fmt::format("- registration preset `{}`; DRR method `{}`; detector {}x{} px at {} mm ({:g} x {:g} mm field), "
                      "source-detector {} mm, source-isocentre {} mm; base seed {}\n",
                      study.setup.preset, DrrRendererFactory::methodName(study.setup.method), d.cols, d.rows,
                      d.pixelSpacing_mm, d.cols * d.pixelSpacing_mm, d.rows * d.pixelSpacing_mm,
                      d.sourceToDetector_mm, d.sourceToIsocentre_mm, study.setup.seed);
  for (const std::string& note : notes) text += "- " + note + "\n";
  text += fmt::format("- success: final mean sTRE < {} mm; sTRE over the CT's bone-surface voxels (>= 250 HU), mTRE over "
                      "a 10x10x10 grid of the bone's bounding box\n\n",
                      PoseErrorMetrics::kSuccessThreshold_mm);
  return text;
}

/// The slice spacing a condition registers on, as used (e.g. "3 mm (original)"), else as asked.
std::string registrationSlices(const StudyCondition& c) {
  if (c.usedSliceSpacing_mm <= 0.0) {
    return c.sliceSpacing_mm > 0 ? fmt::format("{:g} mm", c.sliceSpacing_mm) : std::string("original");
  }
  const bool original = c.sliceSpacing_mm <= 0.0 || c.usedSliceSpacing_mm != c.sliceSpacing_mm;
  return fmt::format("{:.3g} mm{}", c.usedSliceSpacing_mm, original ? " (original)" : "");
}

std::string statsColumns() {
  return "| trials | success | sTRE mean (mm) | sTRE max (mm) | sTRE mean, all (mm) | mTRE (mm) | rot (deg) | "
         "trans (mm) | median time (s) | setup s | DRRs |";
}
std::string statsCells(const ConditionStats& s) {
  return fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.0f} |", s.trials, percent(s),
                     mm(s.streMean_mm), mm(s.streMax_mm), mm(s.streMeanAll_mm), mm(s.mtre_mm), mm(s.rotation_deg),
                     mm(s.translation_mm), mm(s.medianSeconds), mm(s.meanSetupSeconds), s.meanDrrs);
}

std::string table2Section(const StudyDefinition& study, const std::vector<TrialRecord>& records) {
  std::string text = "## Results beside the paper\n\n| CT | scenario | registration slices " + statsColumns() +
                     " paper: mean (max) sTRE (mm) * |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const StudyCondition& c : study.conditions) {
    const ConditionStats s = StudyReport::statistics(recordsOf(study, c, records));
    text += fmt::format("| {} | {} | {} {} {} |\n", c.ct, c.scenario, registrationSlices(c), statsCells(s),
                        paperTable2(c.scenario));
  }
  text += "\n\\* The paper reports in its Table 2 the mean (max) sTRE on simulated X-rays of a clinical pelvis CT "
          "(Knaan & Joskowicz, MICCAI 2003): 0.3 (0.7) mm realistic (Δh 2.4 mm, some objects) and 0.5 (0.7) mm bad "
          "(Δh 4.2 mm), 3 views, 20–100 s. It has no simulated ideal row (in vitro, dry spine: 0.3 (0.4) mm).\n\n";
  return text;
}

/// The capture study's rotation and clinical-setup starts: one row per condition with the initial mean sTRE the
/// starts actually had. Empty when the study has none.
std::string otherStartsSection(const StudyDefinition& study, const std::vector<TrialRecord>& records) {
  std::string rows;
  for (const StudyCondition& c : study.conditions) {
    if (c.start == StudyStart::SurfaceDistance) continue;
    const std::vector<TrialRecord> trials = recordsOf(study, c, records);
    double initialSum = 0.0, initialMax = 0.0;
    int initialCount = 0;
    for (const TrialRecord& r : trials) {
      if (!std::isfinite(r.initialStre_mm)) continue;
      initialSum += r.initialStre_mm;
      initialMax = std::max(initialMax, r.initialStre_mm);
      ++initialCount;
    }
    const ConditionStats s = StudyReport::statistics(trials);
    const std::string start = c.start == StudyStart::Rotation
                                  ? fmt::format("rotation {:g}–{:g}°", c.rotationLow_deg, c.rotationHigh_deg)
                                  : std::string("supine at the isocentre (no landmarks)");
    rows += fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", c.ct, start, s.trials,
                        initialCount ? mm(initialSum / initialCount) : "–", initialCount ? mm(initialMax) : "–",
                        percent(s), mm(s.streMeanAll_mm));
  }
  if (rows.empty()) return "";
  return "## Start rotations and the clinical setup alone (both measures)\n\nRotations are about a random axis through "
         "the bone centre, without translation. The setup start puts the bone centre at the C-arm isocentre with the "
         "CT axes along the table (SetupPose); its trials differ only by the search seed.\n\n"
         "| CT | start | trials | initial sTRE mean (mm) | initial sTRE max (mm) | success | final sTRE mean, all (mm) "
         "|\n|---|---|---|---|---|---|---|\n" +
         rows + "\n";
}

std::string captureSection(const StudyDefinition& study, const std::vector<TrialRecord>& records) {
  std::string text = "## Cumulative failure and final error by initial mean sTRE\n\n";
  std::string ranges = "## Capture range (largest initial-sTRE bin edge up to which every bin has >= 95 % success)\n\n"
                       "| CT | measures | capture range (mm) |\n|---|---|---|\n";
  for (const auto& [name, conditions] : groups(study, true, true)) {
    text += fmt::format("### {}\n\n| initial sTRE bin (mm) | trials | success | cumulative failure | final sTRE mean, all "
                        "(mm) | final sTRE max, all (mm) |\n|---|---|---|---|---|---|\n",
                        name);
    int cumulativeTrials = 0, cumulativeFailures = 0;
    std::vector<InitialDistanceBin> bins;
    for (const StudyCondition* c : conditions) {
      const ConditionStats s = StudyReport::statistics(recordsOf(study, *c, records));
      cumulativeTrials += s.trials;
      cumulativeFailures += s.trials - s.successes;
      bins.push_back(InitialDistanceBin{c->initialLow_mm, c->initialHigh_mm, s.trials, s.successes});
      text += fmt::format("| {:g}–{:g} | {} | {} | {} | {} | {} |\n", c->initialLow_mm, c->initialHigh_mm, s.trials,
                          percent(s),
                          cumulativeTrials ? fmt::format("{:.0f} %", 100.0 * cumulativeFailures / cumulativeTrials) : "–",
                          mm(s.streMeanAll_mm), mm(s.streMaxAll_mm));
    }
    text += "\n";
    // When every bin succeeds, the range is only bounded by the bins tested.
    const double range_mm = PoseErrorMetrics::captureRange_mm(bins);
    const bool everyBin = !bins.empty() && range_mm == bins.back().high_mm;
    ranges += fmt::format("| {} | {} | {}{:g}{} |\n", conditions.front()->ct, conditions.front()->variant,
                          everyBin ? "≥ " : "", range_mm, everyBin ? " (every bin tested)" : "");
  }
  return text + ranges +
         "\nThe paper reports a capture range of about 55 mm on its lamb hip (Knaan & Joskowicz, MICCAI 2003).\n\n" +
         otherStartsSection(study, records);
}

std::string conditionTable(const StudyDefinition& study, const std::vector<TrialRecord>& records, const char* what) {
  std::string text = fmt::format("## Results\n\n| CT | {} {}\n|---|---|---|---|---|---|---|---|---|---|---|---|---|\n", what,
                                 statsColumns());
  for (const StudyCondition& c : study.conditions) {
    const ConditionStats s = StudyReport::statistics(recordsOf(study, c, records));
    text += fmt::format("| {} | {} {}\n", c.ct, c.variant, statsCells(s));
  }
  return text + "\n";
}

std::string failures(const std::vector<TrialRecord>& records, const StudyDefinition& study) {
  std::string text;
  for (const TrialRecord& r : records) {
    if (r.study == study.name && r.status == TrialStatus::Failed) {
      text += fmt::format("- {} trial {}: {}\n", r.condition, r.trial, r.reason);
    }
  }
  return text.empty() ? "" : "## Failed trials (registration error)\n\n" + text + "\n";
}

/// A chart series: statistic `value` of each condition against x = position in `conditions` or `xOf`.
ChartSeries seriesOf(const std::string& name, const std::vector<const StudyCondition*>& conditions,
                     const StudyDefinition& study, const std::vector<TrialRecord>& records,
                     double (*xOf)(const StudyCondition&, std::size_t), double (*value)(const ConditionStats&)) {
  ChartSeries series;
  series.name = name;
  for (std::size_t i = 0; i < conditions.size(); ++i) {
    const ConditionStats s = StudyReport::statistics(recordsOf(study, *conditions[i], records));
    series.x.push_back(xOf(*conditions[i], i));
    series.y.push_back(s.trials ? value(s) : kNan);
  }
  return series;
}

double byIndex(const StudyCondition&, std::size_t i) { return static_cast<double>(i); }
double byViews(const StudyCondition& c, std::size_t) { return c.viewCount; }
double byBinEdge(const StudyCondition& c, std::size_t) { return c.initialHigh_mm; }
double successPercent(const ConditionStats& s) { return 100.0 * s.successRate; }
double streMean(const ConditionStats& s) { return s.streMeanAll_mm; }
double streMax(const ConditionStats& s) { return s.streMaxAll_mm; }
double medianTime(const ConditionStats& s) { return s.medianSeconds; }

/// The charts of a study (file name, spec).
std::vector<std::pair<std::string, ChartSpec>> charts(const StudyDefinition& study,
                                                      const std::vector<TrialRecord>& records) {
  std::vector<std::pair<std::string, ChartSpec>> out;
  if (study.name == "capture") {
    ChartSpec failure{"Cumulative failure by initial mean sTRE", "initial mean sTRE, upper bin edge (mm)",
                      "cumulative failure (%)", {}, {}, 0.0, 100.0};
    ChartSpec error{"Final sTRE by initial mean sTRE (all trials)", "initial mean sTRE, upper bin edge (mm)",
                    "final sTRE (mm)", {}, {}, 0.0, 2.0};
    for (const auto& [name, conditions] : groups(study, true, true)) {
      // Cumulative failure: failures over all trials of the bins up to this one.
      ChartSeries cumulative{name, {}, {}};
      int trials = 0, failuresSoFar = 0;
      for (const StudyCondition* c : conditions) {
        const ConditionStats s = StudyReport::statistics(recordsOf(study, *c, records));
        trials += s.trials;
        failuresSoFar += s.trials - s.successes;
        cumulative.x.push_back(c->initialHigh_mm);
        cumulative.y.push_back(trials ? 100.0 * failuresSoFar / trials : kNan);
      }
      failure.series.push_back(std::move(cumulative));
      error.series.push_back(seriesOf(name + " mean", conditions, study, records, byBinEdge, streMean));
      error.series.push_back(seriesOf(name + " max", conditions, study, records, byBinEdge, streMax));
    }
    out.emplace_back("capture_failure.png", std::move(failure));
    out.emplace_back("capture_stre.png", std::move(error));
  } else if (study.name == "views") {
    ChartSpec success{"Success rate by number of views", "views", "success (%)", {}, {}, 0.0, 100.0};
    ChartSpec error{"Final sTRE by number of views (all trials)", "views", "final sTRE (mm)", {}, {}, 0.0, 1.0};
    for (const auto& [ct, conditions] : groups(study, false)) {
      success.series.push_back(seriesOf(ct, conditions, study, records, byViews, successPercent));
      error.series.push_back(seriesOf(ct + " mean", conditions, study, records, byViews, streMean));
      error.series.push_back(seriesOf(ct + " max", conditions, study, records, byViews, streMax));
    }
    out.emplace_back("views_success.png", std::move(success));
    out.emplace_back("views_stre.png", std::move(error));
  } else {
    // table2 and ablation: one category per variant or scenario, one series per CT.
    const bool table2 = study.name == "table2";
    ChartSpec error{table2 ? "Final mean sTRE by scenario (all trials)" : "Final mean sTRE by technique (all trials)",
                    table2 ? "scenario" : "technique", "final mean sTRE (mm)", {}, {}, 0.0, 1.0};
    ChartSpec secondary{table2 ? "Success rate by scenario" : "Median registration time by technique",
                        table2 ? "scenario" : "technique", table2 ? "success (%)" : "median time (s)", {}, {}, 0.0,
                        table2 ? 100.0 : 1.0};
    for (const auto& [ct, conditions] : groups(study, false)) {
      if (error.categories.empty()) {
        for (const StudyCondition* c : conditions) error.categories.push_back(table2 ? c->scenario : c->variant);
        secondary.categories = error.categories;
      }
      ChartSeries mean = seriesOf(ct, conditions, study, records, byIndex, streMean);
      ChartSeries other = seriesOf(ct, conditions, study, records, byIndex, table2 ? successPercent : medianTime);
      mean.lines = other.lines = false;
      error.series.push_back(std::move(mean));
      secondary.series.push_back(std::move(other));
    }
    out.emplace_back(table2 ? "table2_stre.png" : "ablation_stre.png", std::move(error));
    out.emplace_back(table2 ? "table2_success.png" : "ablation_time.png", std::move(secondary));
  }
  return out;
}

}  // namespace

ConditionStats StudyReport::statistics(const std::vector<TrialRecord>& records) {
  ConditionStats s;
  std::vector<double> seconds;
  double sumMean = 0, sumMeanAll = 0, sumMaxAll = 0, sumMtre = 0, sumRot = 0, sumTrans = 0, sumDrrs = 0, sumSetup = 0;
  int registered = 0;
  s.streMax_mm = kNan;
  for (const TrialRecord& r : records) {
    if (r.status == TrialStatus::Cancelled) continue;
    ++s.trials;
    if (r.status != TrialStatus::Ok) continue;
    ++registered;
    seconds.push_back(r.seconds);
    sumDrrs += static_cast<double>(r.drrs);
    sumSetup += r.setupSeconds;
    sumMeanAll += r.error.streMean_mm;
    sumMaxAll += r.error.streMax_mm;
    if (!r.success) continue;
    ++s.successes;
    sumMean += r.error.streMean_mm;
    s.streMax_mm = std::isnan(s.streMax_mm) ? r.error.streMax_mm : std::max(s.streMax_mm, r.error.streMax_mm);
    sumMtre += r.error.mtre_mm;
    sumRot += r.error.rotation_deg;
    sumTrans += r.error.translation_mm;
  }
  s.successRate = s.trials ? static_cast<double>(s.successes) / s.trials : 0.0;
  const auto mean = [](double sum, int n) { return n ? sum / n : kNan; };
  s.streMean_mm = mean(sumMean, s.successes);
  s.mtre_mm = mean(sumMtre, s.successes);
  s.rotation_deg = mean(sumRot, s.successes);
  s.translation_mm = mean(sumTrans, s.successes);
  s.streMeanAll_mm = mean(sumMeanAll, registered);
  s.streMaxAll_mm = mean(sumMaxAll, registered);
  s.meanDrrs = registered ? sumDrrs / registered : 0.0;
  s.meanSetupSeconds = mean(sumSetup, registered);
  if (seconds.empty()) {
    s.medianSeconds = kNan;
  } else {
    std::sort(seconds.begin(), seconds.end());
    const std::size_t n = seconds.size();
    s.medianSeconds = n % 2 ? seconds[n / 2] : 0.5 * (seconds[n / 2 - 1] + seconds[n / 2]);
  }
  return s;
}

std::string StudyReport::markdown(const StudyDefinition& study, const std::vector<TrialRecord>& records,
                                  const std::vector<std::string>& notes) {
  std::string text = header(study, notes);
  if (study.name == "table2") {
    text += table2Section(study, records);
  } else if (study.name == "capture") {
    text += captureSection(study, records);
  } else {
    text += conditionTable(study, records, study.name == "views" ? "views" : "technique");
  }
  text += "success: successes / finished trials and the one-sided 95 % Clopper–Pearson lower bound on the rate. "
          "sTRE mean/max, mTRE, rot, trans: over successful trials (max = largest); \"all\": every registered trial; "
          "time and DRRs: every registered trial.\n\n";
  if (!study.gaps.empty()) {
    text += "## Not measured\n\n";
    for (const std::string& gap : study.gaps) text += "- " + gap + "\n";
    text += "\n";
  }
  text += failures(records, study);
  text += "## Charts\n\n";
  for (const auto& [file, spec] : charts(study, records)) text += fmt::format("![{}]({})\n\n", spec.title, file);
  return text;
}

Result<std::vector<std::filesystem::path>> StudyReport::write(const StudyDefinition& study,
                                                              const std::vector<TrialRecord>& records,
                                                              const std::vector<std::string>& notes,
                                                              const std::filesystem::path& outDir) {
  std::vector<std::filesystem::path> written;
  for (const auto& [file, spec] : charts(study, records)) {
    const std::filesystem::path path = outDir / file;
    if (Status ok = LineChart::writePng(spec, path); !ok) return fail(fmt::format("chart {}: {}", file, ok.error()));
    written.push_back(path);
  }
  const std::filesystem::path report = outDir / "report.md";
  if (Status ok = TextFile::writeAtomically(report, markdown(study, records, notes)); !ok) return fail(ok.error());
  written.push_back(report);
  return written;
}

}  // namespace fct
