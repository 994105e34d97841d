// DrrBenchmark: times the DRR methods on the real CTs against plastimatch's exact DRR in the same run, with the same
// geometry (800 x 600 detector, 0.5 mm pixels, SID 1500 mm, SAD 1000 mm, AP view, isocentre at the volume centre) and
// the same thread count. Prints a table and one `ratio X/Y case: value` line per comparison. Not a test: it asserts
// nothing; run it with Testing/Benchmarks/run_drr_benchmark.sh.

#include <CLI/CLI.hpp>
#include <fmt/core.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <numeric>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "Drr/DrrRendererFactory.h"
#include "Drr/DrrVolume.h"
#include "Drr/SiddonRayCaster.h"
#include "Drr/TransgraphRenderer.h"
#include "Geometry/Camera.h"
#include "Geometry/RigidPose.h"
#include "IO/Dicom/DicomSeriesReader.h"
#include "IO/Project/ViewFile.h"
#include "IO/Volume/VolumeFileIO.h"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr int kCols = 800, kRows = 600;
constexpr double kPixel_mm = 0.5, kSid_mm = 1500.0, kSad_mm = 1000.0;

struct Options {
  fs::path dataDir;
  fs::path workDir = fs::temp_directory_path() / "fluoroct-drr-benchmark";
  int threads = 2;
  int repeats = 3;
  double transgraphRays = 15e6;
  double offsetFactor = 3.0;  // Transgraph offset step / plane step (the library's default)
  int nccPoses = 20;
  bool plastimatch = true;
  int wholeProcessViews = 0;  // > 0: only the whole-process comparison, `fluoroct drr` vs `plastimatch drr`
  fs::path fluoroct;          // the fluoroct program of the whole-process comparison
};

struct Row {
  std::string ctName, method;
  int threads = 0;
  double full_s = NAN, roi_s = NAN, ncc = NAN;
  std::string note;
};

double seconds(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Median wall time of `repeats` calls after one warm-up call.
double medianTime(int repeats, const std::function<void()>& run) {
  run();
  std::vector<double> times;
  for (int i = 0; i < repeats; ++i) {
    const auto start = Clock::now();
    run();
    times.push_back(seconds(start));
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

double ncc(const std::vector<float>& a, const std::vector<float>& b) {
  const std::size_t n = std::min(a.size(), b.size());
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < n; ++i) ma += a[i], mb += b[i];
  ma /= n;
  mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double x = a[i] - ma, y = b[i] - mb;
    sab += x * y, saa += x * x, sbb += y * y;
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : NAN;
}

// plastimatch ignores direction cosines, so hand it (and ourselves) a volume whose direction is the identity:
// axes with a -1 direction cosine are reversed in memory (exact, no resampling). Fails on oblique volumes.
fct::Result<fct::Volume> withIdentityDirection(const fct::Volume& ct) {
  const Eigen::Matrix3d& D = ct.direction_lps();
  Eigen::Vector3d sign;
  for (int a = 0; a < 3; ++a) {
    sign[a] = D(a, a) > 0 ? 1.0 : -1.0;
    if ((D.col(a) - sign[a] * Eigen::Vector3d::Unit(a)).cwiseAbs().maxCoeff() > 1e-6) {
      return fct::fail("the CT is not axis-aligned; plastimatch needs an identity direction");
    }
  }
  const Eigen::Vector3i n = ct.dims();
  Eigen::Vector3d lastIndex = (n.cast<double>().array() - 1.0).matrix();
  Eigen::Vector3d firstCorner(sign[0] > 0 ? 0 : lastIndex[0], sign[1] > 0 ? 0 : lastIndex[1],
                              sign[2] > 0 ? 0 : lastIndex[2]);
  auto made = fct::Volume::create(n, ct.spacing_mm(), ct.lpsFromIjk(firstCorner));
  if (!made) return made;
  fct::Volume out = std::move(made.value());
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) {
        out.at(i, j, k) = ct.at(sign[0] > 0 ? i : n.x() - 1 - i, sign[1] > 0 ? j : n.y() - 1 - j,
                                sign[2] > 0 ? k : n.z() - 1 - k);
      }
    }
  }
  out.description = ct.description;
  return out;
}

// Reads a plastimatch PFM (top row first, as plastimatch writes it).
fct::Result<std::vector<float>> readPfm(const fs::path& path, int cols, int rows) {
  std::ifstream in(path, std::ios::binary);
  std::string magic;
  int w = 0, h = 0;
  double scale = 0;
  in >> magic >> w >> h >> scale;
  in.get();
  if (!in || magic != "Pf" || w != cols || h != rows) {
    return fct::fail(fmt::format("{} is not a {} x {} PFM image", path.string(), cols, rows));
  }
  std::vector<float> pixels(static_cast<std::size_t>(cols) * rows);
  in.read(reinterpret_cast<char*>(pixels.data()), static_cast<std::streamsize>(pixels.size() * sizeof(float)));
  if (!in) return fct::fail(fmt::format("{} is truncated", path.string()));
  return pixels;
}

struct PlastimatchRun {
  double total_s = NAN;
  std::vector<float> image;
  std::string error;
};

// Runs `plastimatch drr -i exact` with the benchmark geometry and parses its own "Total time".
PlastimatchRun runPlastimatch(const fs::path& mha, const fs::path& prefix, const Eigen::Vector3d& isocentre_lps_mm,
                              int threads) {
  PlastimatchRun run;
  // plastimatch: -r and -z are "columns rows" in practice (its PFM header confirms), nrm points from the isocentre
  // to the source, vup to detector row 0. This is exactly Camera::lookingAt with the AP rotation used below.
  const std::string command = fmt::format(
      "OMP_NUM_THREADS={} plastimatch drr -A cpu -i exact -t pfm --sad {} --sid {} -r \"{} {}\" -z \"{} {}\" "
      "-o \"{} {} {}\" -n \"0 -1 0\" --vup \"0 0 1\" -O \"{}\" \"{}\" 2>&1",
      threads, kSad_mm, kSid_mm, kCols, kRows, kCols * kPixel_mm, kRows * kPixel_mm, isocentre_lps_mm.x(),
      isocentre_lps_mm.y(), isocentre_lps_mm.z(), prefix.string(), mha.string());
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) {
    run.error = "cannot start plastimatch";
    return run;
  }
  std::string output;
  std::array<char, 4096> buffer;
  while (std::fgets(buffer.data(), buffer.size(), pipe)) output += buffer.data();
  const int status = ::pclose(pipe);
  std::smatch match;
  if (status != 0 || !std::regex_search(output, match, std::regex(R"(Total time:\s*([0-9.eE+-]+))"))) {
    run.error = "plastimatch failed: " + output.substr(0, 300);
    return run;
  }
  run.total_s = std::stod(match[1]);
  auto image = readPfm(prefix.string() + "0000.pfm", kCols, kRows);
  if (!image) {
    run.error = image.error();
    return run;
  }
  run.image = std::move(image.value());
  return run;
}

// ~12 % of the level's pixels as non-overlapping 7 x 7 windows at random places (the registration's ROI workload).
fct::PixelIndexList roiPixels(int cols, int rows, double fraction, unsigned seed) {
  std::vector<std::pair<int, int>> windows;
  for (int r = 0; r + 7 <= rows; r += 7) {
    for (int c = 0; c + 7 <= cols; c += 7) windows.emplace_back(c, r);
  }
  std::mt19937 random(seed);
  std::shuffle(windows.begin(), windows.end(), random);
  const std::size_t wanted = static_cast<std::size_t>(std::round(fraction * cols * rows / 49.0));
  windows.resize(std::min(wanted, windows.size()));
  fct::PixelIndexList pixels;
  for (const auto& [c0, r0] : windows) {
    for (int r = r0; r < r0 + 7; ++r) {
      for (int c = c0; c < c0 + 7; ++c) pixels.push_back(r * cols + c);
    }
  }
  std::sort(pixels.begin(), pixels.end());
  return pixels;
}

// Spacing that gives about `targetRays` rays for this view and range (rays scale with spacing^-4).
fct::Result<fct::TransgraphParameters> parametersForRays(const fct::Volume& ct, const fct::Camera& view,
                                                         const Eigen::Isometry3d& pose, double targetRays,
                                                         double offsetFactor) {
  fct::TransgraphParameters p;
  p.maxRays = static_cast<std::size_t>(1e12);
  p.spacing_mm = 4.0;
  for (int i = 0; i < 6; ++i) {
    p.offsetSpacing_mm = offsetFactor * p.spacing_mm;
    auto layout = fct::Transgraph::plan(ct, view, pose, p);
    if (!layout) return fct::fail(layout.error());
    const double ratio = static_cast<double>(layout.value().rayCount()) / targetRays;
    if (std::abs(ratio - 1.0) < 0.03) break;
    p.spacing_mm *= std::pow(ratio, 0.25);
  }
  p.spacing_mm = std::round(p.spacing_mm * 100.0) / 100.0;
  p.offsetSpacing_mm = offsetFactor * p.spacing_mm;
  return p;
}

void benchmarkCt(const std::string& name, const fct::Volume& ctIn, const Options& options, std::vector<Row>& rows,
                 std::vector<std::string>& ratios) {
  fmt::print("== {}: {} x {} x {} voxels, {:.3f} x {:.3f} x {:.3f} mm\n", name, ctIn.dims().x(), ctIn.dims().y(),
             ctIn.dims().z(), ctIn.spacing_mm().x(), ctIn.spacing_mm().y(), ctIn.spacing_mm().z());
  auto identity = withIdentityDirection(ctIn);
  if (!identity) {
    fmt::print("   skipped: {}\n", identity.error());
    return;
  }
  const fct::Volume& ct = identity.value();
  auto prepared = fct::DrrVolume::create(ct);
  if (!prepared) {
    fmt::print("   skipped: {}\n", prepared.error());
    return;
  }
  const auto volume = std::make_shared<const fct::DrrVolume>(std::move(prepared.value()));
  const Eigen::Vector3d isocentre = ct.centre_lps_mm();
  Eigen::Matrix3d R_ap;  // camera x = patient left (+x), y = inferior (-z), z = anterior -> posterior (+y)
  R_ap.col(0) = Eigen::Vector3d::UnitX();
  R_ap.col(1) = -Eigen::Vector3d::UnitZ();
  R_ap.col(2) = Eigen::Vector3d::UnitY();
  const fct::Camera view = fct::Camera::lookingAt(isocentre, R_ap, kSad_mm, kSid_mm, kCols, kRows, kPixel_mm);
  const Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  const fct::Camera level2 = view.downsampled(2);
  const fct::PixelIndexList roi = roiPixels(level2.intrinsics().cols, level2.intrinsics().rows, 0.12, 5);
  fmt::print("   ROI workload: {} of {} level-2 pixels ({:.1f} %)\n", roi.size(),
             level2.intrinsics().cols * level2.intrinsics().rows,
             100.0 * roi.size() / (level2.intrinsics().cols * level2.intrinsics().rows));

  fct::DrrRendererOptions siddonOptions, raycastOptions;
  siddonOptions.method = fct::DrrMethod::Siddon;
  raycastOptions.method = fct::DrrMethod::RayCast;
  std::unique_ptr<fct::DrrRenderer> siddon = std::move(fct::DrrRendererFactory::create(volume, siddonOptions).value());
  std::unique_ptr<fct::DrrRenderer> raycast = std::move(fct::DrrRendererFactory::create(volume, raycastOptions).value());
  fct::FloatImage siddonImage;
  {
    tbb::global_control control(tbb::global_control::max_allowed_parallelism, options.threads);
    (void)siddon->render(view, pose, 0, siddonImage);
  }

  // 1. plastimatch's exact DRR.
  double plastimatch_s = NAN;
  if (options.plastimatch) {
    fs::create_directories(options.workDir);
    const fs::path mha = options.workDir / (name + ".mha");
    if (auto written = fct::VolumeFileIO::write(ct, mha); !written) {
      fmt::print("   plastimatch skipped: {}\n", written.error());
    } else {
      std::vector<double> times;
      PlastimatchRun run;
      for (int i = 0; i < options.repeats; ++i) {
        run = runPlastimatch(mha, options.workDir / (name + "_plastimatch"), isocentre, options.threads);
        if (!run.error.empty()) break;
        times.push_back(run.total_s);
      }
      if (run.error.empty()) {
        std::sort(times.begin(), times.end());
        plastimatch_s = times[times.size() / 2];
        rows.push_back({name, "plastimatch_exact", options.threads, plastimatch_s, NAN,
                        ncc(run.image, siddonImage.pixels), "NCC vs our siddon"});
      } else {
        fmt::print("   plastimatch skipped: {}\n", run.error);
      }
      fs::remove(mha);
    }
  }

  // 2. Our ray casters, full DRR and ROI, 1 thread and `threads`.
  struct Timed {
    double full1 = NAN, fullN = NAN, roiN = NAN;
  };
  const auto timeRenderer = [&](const fct::DrrRenderer& renderer, const std::string& method, double nccValue,
                                const std::string& note) {
    Timed timed;
    fct::FloatImage image;
    std::vector<float> values;
    for (int threads : {1, options.threads}) {
      tbb::global_control control(tbb::global_control::max_allowed_parallelism, threads);
      const double full = medianTime(options.repeats, [&] { (void)renderer.render(view, pose, 0, image); });
      const double roiTime = medianTime(options.repeats, [&] { (void)renderer.renderPixels(view, pose, 2, roi, values); });
      (threads == 1 ? timed.full1 : timed.fullN) = full;
      timed.roiN = roiTime;
      rows.push_back({name, method, threads, full, roiTime, threads == options.threads ? nccValue : NAN, note});
      if (options.threads == 1) break;
    }
    return timed;
  };
  fct::FloatImage raycastImage;
  (void)raycast->render(view, pose, 0, raycastImage);
  const Timed siddonTime = timeRenderer(*siddon, "siddon", NAN, "");
  // The one-ray-at-a-time walk, against which the AVX-512 packets of the default are measured.
  const fct::SiddonRayCaster siddonScalar(volume, fct::SiddonTraversal::Scalar);
  fct::FloatImage scalarImage;
  (void)siddonScalar.render(view, pose, 0, scalarImage);
  const Timed scalarTime = timeRenderer(siddonScalar, "siddon_scalar", ncc(scalarImage.pixels, siddonImage.pixels),
                                        "NCC vs siddon");
  const Timed raycastTime =
      timeRenderer(*raycast, "raycast", ncc(raycastImage.pixels, siddonImage.pixels), "NCC vs siddon");

  // 3. Transgraph at about the paper's size.
  Timed transgraphTime;
  auto parameters = parametersForRays(ct, view, pose, options.transgraphRays, options.offsetFactor);
  if (!parameters) {
    fmt::print("   transgraph skipped: {}\n", parameters.error());
  } else {
    tbb::global_control control(tbb::global_control::max_allowed_parallelism, options.threads);
    auto created = fct::TransgraphRenderer::create(volume, view, pose, parameters.value());
    if (!created) {
      fmt::print("   transgraph skipped: {}\n", created.error());
    } else {
      const fct::TransgraphRenderer& transgraph = *created.value();
      const fct::Transgraph& table = transgraph.transgraph();
      const auto& counts = table.layout().counts;
      fmt::print("   transgraph: spacing {:.2f} mm (offsets {:.2f} mm), range ±{} deg ±{} mm, {} x {} x {} x {} = {:.2f} M rays, "
                 "{:.1f} MB, built in {:.2f} s with {} threads\n",
                 table.layout().step_mm[0], table.layout().step_mm[2], parameters.value().range.rotation_deg,
                 parameters.value().range.translation_mm, counts[0], counts[1], counts[2], counts[3],
                 table.rayCount() / 1e6, table.memory_bytes() / 1e6, table.buildInfo().build_s, options.threads);
      // NCC with the exact ray caster at random poses inside the validity range.
      std::mt19937 random(3);
      std::uniform_real_distribution<double> unit(-1.0, 1.0);
      const auto& range = parameters.value().range;
      std::vector<double> nccs;
      std::size_t fallbacks = 0;
      fct::FloatImage a, b;
      for (int i = 0; i < options.nccPoses; ++i) {
        const fct::PoseParameters delta{
            range.rotation_deg * Eigen::Vector3d(unit(random), unit(random), unit(random)),
            range.translation_mm * Eigen::Vector3d(unit(random), unit(random), unit(random))};
        const Eigen::Isometry3d p = fct::RigidPose::toTransform(delta, pose * ct.centre_lps_mm()) * pose;
        fct::DrrRenderStats stats;
        (void)transgraph.render(view, p, 0, a, &stats);
        fallbacks += stats.fallbackRays;
        (void)siddon->render(view, p, 0, b);
        nccs.push_back(ncc(a.pixels, b.pixels));
      }
      const double nccMin = *std::min_element(nccs.begin(), nccs.end());
      const double nccMean = std::accumulate(nccs.begin(), nccs.end(), 0.0) / nccs.size();
      fmt::print("   transgraph vs siddon at {} random poses in range: NCC min {:.4f}, mean {:.4f}; fallback rays {}\n",
                 nccs.size(), nccMin, nccMean, fallbacks);
      transgraphTime = timeRenderer(transgraph, "transgraph", nccMin, "min NCC vs siddon, 20 poses");
      ratios.push_back(fmt::format("transgraph build_s {}: {:.2f}", name, table.buildInfo().build_s));
      ratios.push_back(fmt::format("transgraph rays {}: {}", name, table.rayCount()));
      ratios.push_back(fmt::format("transgraph memory_bytes {}: {}", name, table.memory_bytes()));
      ratios.push_back(fmt::format("ncc transgraph/siddon min {}: {:.4f}", name, nccMin));
    }
  }

  const auto ratio = [&](const std::string& what, double a, double b) {
    if (std::isfinite(a) && std::isfinite(b) && b > 0) ratios.push_back(fmt::format("ratio {} {}: {:.3f}", what, name, a / b));
  };
  ratio("siddon/plastimatch_exact", siddonTime.fullN, plastimatch_s);
  ratio("siddon/siddon_scalar", siddonTime.fullN, scalarTime.fullN);
  ratio("roi_siddon/roi_siddon_scalar", siddonTime.roiN, scalarTime.roiN);
  ratio("raycast/plastimatch_exact", raycastTime.fullN, plastimatch_s);
  ratio("transgraph/raycast", transgraphTime.fullN, raycastTime.fullN);
  ratio("transgraph/siddon", transgraphTime.fullN, siddonTime.fullN);
  ratio("roi_transgraph/roi_siddon", transgraphTime.roiN, siddonTime.roiN);
  ratio("roi_raycast/roi_siddon", raycastTime.roiN, siddonTime.roiN);
  if (options.threads > 1) {
    const std::string t = fmt::format("{}threads/1thread", options.threads);
    ratio(t + " siddon", siddonTime.fullN, siddonTime.full1);
    ratio(t + " raycast", raycastTime.fullN, raycastTime.full1);
    ratio(t + " transgraph", transgraphTime.fullN, transgraphTime.full1);
  }
}

// Wall time of a shell command (its output goes to `log`); NAN when it fails.
double timedCommand(const std::string& command, const fs::path& log) {
  const auto start = Clock::now();
  const int status = std::system(fmt::format("{} > \"{}\" 2>&1", command, log.string()).c_str());
  return status == 0 ? seconds(start) : NAN;
}

// Whole process, the way a user runs each program: `fluoroct drr` reads the DICOM series and renders `viewCount`
// views of 800 x 600 in one call; `plastimatch drr -A cpu -i exact` reads the CT (a MetaImage of max(HU + 1000, 0)
// with an identity direction, `-P none`, so both integrate proportional values) and renders the same views as one
// gantry rotation (`-a N -N 360/N`: image k has its source at isocentre + SAD (cos a, -sin a, 0), a = k 360/N, vup +z). Median wall time of
// `repeats` runs each, alternating; NCC per view between the two programs' output files.
void wholeProcess(const fs::path& dicomFolder, const Options& options, std::vector<std::string>& ratios) {
  auto read = fct::DicomSeriesReader::read(dicomFolder);
  if (!read) {
    fmt::print("whole-process comparison skipped: {}\n", read.error());
    return;
  }
  auto identity = withIdentityDirection(read.value());
  if (!identity) {
    fmt::print("whole-process comparison skipped: {}\n", identity.error());
    return;
  }
  fct::Volume shifted = identity.value();
  for (float& v : shifted.voxels()) v = std::max(v + 1000.0f, 0.0f);
  fs::create_directories(options.workDir);
  const fs::path mha = options.workDir / "head_shifted.mha";
  if (auto written = fct::VolumeFileIO::write(shifted, mha); !written) {
    fmt::print("whole-process comparison skipped: {}\n", written.error());
    return;
  }
  const Eigen::Vector3d isocentre = identity.value().centre_lps_mm();
  const int n = options.wholeProcessViews;
  const double step_deg = 360.0 / n;
  std::vector<fct::ViewSpec> views;
  for (int k = 0; k < n; ++k) {
    const double a = k * step_deg * M_PI / 180.0;
    const Eigen::Vector3d nrm(std::cos(a), -std::sin(a), 0.0), vup = Eigen::Vector3d::UnitZ();
    Eigen::Matrix3d R;  // camera z from the source to the detector, x along the columns, y down the rows
    R.col(2) = -nrm;
    R.col(0) = vup.cross(nrm).normalized();
    R.col(1) = R.col(2).cross(R.col(0));
    fct::ViewSpec view;
    view.name = fmt::format("g{:03.0f}", k * step_deg);
    view.camera = fct::Camera::lookingAt(isocentre, R, kSad_mm, kSid_mm, kCols, kRows, kPixel_mm);
    views.push_back(view);
  }
  const fs::path viewFile = options.workDir / "views8.json";
  if (auto written = fct::ViewFile::write(views, viewFile); !written) {
    fmt::print("whole-process comparison skipped: {}\n", written.error());
    return;
  }
  const std::string ours = fmt::format("\"{}\" drr --ct \"{}\" --views \"{}\" --out \"{}\"", options.fluoroct.string(),
                                       dicomFolder.string(), viewFile.string(), (options.workDir / "ours.pfm").string());
  const std::string theirs = fmt::format(
      "OMP_NUM_THREADS={} plastimatch drr -A cpu -i exact -P none -t pfm --sad {} --sid {} -r \"{} {}\" -z \"{} {}\" "
      "-o \"{} {} {}\" -a {} -N {} --vup \"0 0 1\" -O \"{}\" \"{}\"",
      options.threads, kSad_mm, kSid_mm, kCols, kRows, kCols * kPixel_mm, kRows * kPixel_mm, isocentre.x(),
      isocentre.y(), isocentre.z(), n, step_deg, (options.workDir / "theirs_").string(), mha.string());
  std::vector<double> oursTimes, theirsTimes;
  for (int i = 0; i < options.repeats; ++i) {
    oursTimes.push_back(timedCommand(ours, options.workDir / "ours.log"));
    theirsTimes.push_back(timedCommand(theirs, options.workDir / "theirs.log"));
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  const double ours_s = median(oursTimes), theirs_s = median(theirsTimes);
  const auto list = [](const std::vector<double>& v) {
    std::string text;
    for (const double s : v) text += fmt::format("{}{:.3f}", text.empty() ? "" : " ", s);
    return text;
  };
  fmt::print("   runs, alternating: fluoroct drr {} s; plastimatch {} s\n", list(oursTimes), list(theirsTimes));
  double nccMin = 1.0;
  for (int k = 0; k < n; ++k) {
    auto a = readPfm(options.workDir / fmt::format("ours_{}.pfm", views[static_cast<std::size_t>(k)].name), kCols, kRows);
    auto b = readPfm(options.workDir / fmt::format("theirs_{:04d}.pfm", k), kCols, kRows);
    if (!a || !b) {
      fmt::print("whole-process comparison: {}\n", !a ? a.error() : b.error());
      nccMin = NAN;
      break;
    }
    // Our PFM is stored bottom row first (the PFM convention), plastimatch's top row first.
    std::vector<float> flipped(a.value().size());
    for (int r = 0; r < kRows; ++r) {
      std::copy_n(a.value().begin() + static_cast<std::ptrdiff_t>(r) * kCols, kCols,
                  flipped.begin() + static_cast<std::ptrdiff_t>(kRows - 1 - r) * kCols);
    }
    nccMin = std::min(nccMin, ncc(flipped, b.value()));
  }
  fmt::print("== whole process, head, {} views of {}x{}: fluoroct drr {:.3f} s, plastimatch drr -i exact {:.3f} s "
             "(median of {}), NCC min over views {:.5f}\n",
             n, kCols, kRows, ours_s, theirs_s, options.repeats, nccMin);
  ratios.push_back(fmt::format("whole_process fluoroct_drr_s head: {:.3f}", ours_s));
  ratios.push_back(fmt::format("whole_process plastimatch_exact_s head: {:.3f}", theirs_s));
  ratios.push_back(fmt::format("ratio whole_process plastimatch_exact/fluoroct_drr head: {:.2f}", theirs_s / ours_s));
  ratios.push_back(fmt::format("ncc whole_process fluoroct/plastimatch min head: {:.5f}", nccMin));
  fs::remove(mha);
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  if (const char* env = std::getenv("FLUOROCT_DATA_DIR"); env && *env) {
    options.dataDir = env;
  } else {
    options.dataDir = FCT_DEFAULT_DATA_DIR;
  }
  CLI::App app{"DRR benchmark: plastimatch drr -i exact vs our Siddon, trilinear ray caster and Transgraph"};
  app.add_option("--data", options.dataDir, "shared data folder (holds ct/)");
  app.add_option("--threads", options.threads, "thread count for every method (plastimatch: OMP_NUM_THREADS)")
      ->check(CLI::Range(1, 256));
  app.add_option("--repeats", options.repeats, "timed repetitions per measurement (median)")->check(CLI::Range(1, 100));
  app.add_option("--transgraph-rays", options.transgraphRays, "target Transgraph size in rays (paper: ~15 M)");
  app.add_option("--transgraph-offset-factor", options.offsetFactor, "Transgraph offset step over plane step")
      ->check(CLI::Range(0.25, 8.0));
  app.add_option("--ncc-poses", options.nccPoses, "random poses for the Transgraph NCC")->check(CLI::Range(1, 1000));
  app.add_option("--work", options.workDir, "scratch folder for plastimatch's input and output");
  app.add_option("--whole-process", options.wholeProcessViews,
                 "only the whole-process comparison on the head: fluoroct drr vs plastimatch drr, N views")
      ->check(CLI::Range(1, 360));
  bool noPlastimatch = false;
  app.add_flag("--no-plastimatch", noPlastimatch, "skip the plastimatch comparison");
  CLI11_PARSE(app, argc, argv);
  options.plastimatch = !noPlastimatch && std::system("plastimatch --version > /dev/null 2>&1") == 0;
  if (!noPlastimatch && !options.plastimatch) fmt::print("plastimatch not found: its rows are skipped\n");

  std::vector<Row> rows;
  std::vector<std::string> ratios;
  if (options.wholeProcessViews > 0) {
    options.fluoroct = fs::path(argv[0]).parent_path() / "fluoroct";
    if (options.plastimatch) wholeProcess(options.dataDir / "ct/head_phantom_philips_bone", options, ratios);
    for (const auto& line : ratios) fmt::print("{}\n", line);
    return 0;
  }
  const fs::path pelvisPath = options.dataDir / "ct/pelvis_totalseg.nii.gz";
  if (auto pelvis = fct::VolumeFileIO::read(pelvisPath); pelvis) {
    benchmarkCt("pelvis", pelvis.value(), options, rows, ratios);
  } else {
    fmt::print("pelvis skipped: {}\n", pelvis.error());
  }
  const fs::path headPath = options.dataDir / "ct/head_phantom_philips_bone";
  if (auto head = fct::DicomSeriesReader::read(headPath); head) {
    benchmarkCt("head", head.value(), options, rows, ratios);
  } else {
    fmt::print("head skipped: {}\n", head.error());
  }

  fmt::print("\n{:<8} {:<18} {:>7} {:>12} {:>14} {:>8}  {}\n", "ct", "method", "threads", "full DRR ms",
             "ROI lvl2 ms", "NCC", "note");
  for (const Row& r : rows) {
    const auto ms = [](double s) { return std::isfinite(s) ? fmt::format("{:.2f}", 1e3 * s) : std::string("-"); };
    fmt::print("{:<8} {:<18} {:>7} {:>12} {:>14} {:>8}  {}\n", r.ctName, r.method, r.threads, ms(r.full_s),
               ms(r.roi_s), std::isfinite(r.ncc) ? fmt::format("{:.4f}", r.ncc) : "-", r.note);
  }
  fmt::print("\n");
  for (const auto& line : ratios) fmt::print("{}\n", line);
  return 0;
}
