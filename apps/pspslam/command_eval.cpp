// `pspslam eval`: ATE and RPE of an estimated trajectory, as TUM's evaluate_ate.py /
// evaluate_rpe.py compute them; the numerics live in pspslam_eval.
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "flag_checks.h"
#include "pspslam/core/error.h"
#include "pspslam/core/output_paths.h"
#include "pspslam/eval/ate.h"
#include "pspslam/eval/plots.h"
#include "pspslam/eval/report.h"
#include "pspslam/eval/rpe.h"
#include "pspslam/io/trajectory_io.h"

namespace pspslam::cli {

namespace {

// The stats.json that `pspslam run` writes beside its trajectories, when there is one. One that
// does not parse only loses what eval reads from it (a plot title, the automatic Sim(3)): the
// evaluation itself does not need it.
std::optional<nlohmann::json> run_stats(const std::string& estimate_file) {
  const std::filesystem::path stats_file =
      std::filesystem::path(estimate_file).parent_path() / "stats.json";
  std::error_code failure;
  if (!std::filesystem::is_regular_file(stats_file, failure)) return std::nullopt;
  try {
    std::ifstream stream(stats_file);
    return nlohmann::json::parse(stream);
  } catch (const nlohmann::json::exception& e) {
    spdlog::warn("{}: not read for the plot titles or the alignment: {}", stats_file.string(),
                 e.what());
    return std::nullopt;
  }
}

// Names the run in plot titles: `--title` when given; else "<sequence folder>, mode <mode>" from
// the run's stats.json; else nothing.
std::string plot_run_name(const std::string& title, const std::optional<nlohmann::json>& run) {
  if (!title.empty()) return title;
  if (!run) return {};
  const nlohmann::json& stats = *run;
  std::string name;
  if (stats.contains("sequence") && stats["sequence"].is_string()) {
    // `run` records the sequence folder; its last component names the sequence.
    std::filesystem::path sequence = stats["sequence"].get<std::string>();
    if (!sequence.has_filename()) sequence = sequence.parent_path();
    name = sequence.filename().string();
  }
  if (stats.contains("mode") && stats["mode"].is_string()) {
    name += (name.empty() ? "" : ", ") + std::string("mode ") + stats["mode"].get<std::string>();
  }
  return name;
}

std::string rpe_delta_text(const RpeOptions& rpe) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%g %s", rpe.delta,
                rpe.unit == RpeDeltaUnit::seconds ? "s" : "frames");
  return buffer;
}

// A monocular run's trajectory has its own scale: unless --sim3 was given, its stats.json
// (`sensor: monocular`) turns Sim(3) alignment on, and the report says why.
void choose_alignment(EvalSettings& settings, const std::optional<nlohmann::json>& stats) {
  if (settings.ate.sim3) {
    settings.alignment_reason = "--sim3";
    return;
  }
  if (stats && stats->is_object() && stats->contains("sensor") &&
      (*stats)["sensor"] == "monocular") {
    settings.ate.sim3 = true;
    settings.alignment_reason = "the run's stats.json says sensor monocular";
  }
}

int evaluate(EvalSettings settings, bool json, const std::string& plot, const std::string& title) {
  const std::optional<nlohmann::json> stats = run_stats(settings.estimate_file);
  choose_alignment(settings, stats);
  if (!plot.empty()) prepare_output_folder(plot, "--plot");
  Trajectory ground_truth = read_tum_trajectory(settings.ground_truth_file);
  if (!settings.gt_body_to_camera_file.empty()) {
    ground_truth =
        body_to_camera(ground_truth, read_rigid_transform(settings.gt_body_to_camera_file));
  }
  const Trajectory estimate = read_tum_trajectory(settings.estimate_file);
  if (estimate.empty()) throw Error(settings.estimate_file + ": trajectory has no pose");
  if (ground_truth.empty()) throw Error(settings.ground_truth_file + ": trajectory has no pose");
  const AteResult ate = compute_ate(ground_truth, estimate, settings.ate);
  const RpeResult rpe = compute_rpe(ground_truth, estimate, settings.rpe);

  std::cout << (json ? format_eval_json(settings, ate, rpe)
                     : format_eval_table(settings, ate, rpe));
  if (!plot.empty()) {
    EvalPlotOptions options;
    options.run_name = plot_run_name(title, stats);
    options.alignment_name = settings.ate.sim3 ? "Sim(3)" : "SE(3)";
    options.rpe_delta = rpe_delta_text(settings.rpe);
    const EvalPlotFiles files = write_eval_plots(ground_truth, estimate, ate, rpe, plot, options);
    // Keep stdout pure JSON under --json: the plot list goes to stderr.
    std::ostream& note = json ? std::cerr : std::cout;
    note << "plots:";
    for (const auto& file : files.files) note << " " << file.string();
    note << "\n";
  }
  return 0;
}

}  // namespace

Command add_eval_command(CLI::App& root) {
  CLI::App* app = root.add_subcommand(
      "eval",
      "ATE / RPE of an estimated trajectory against ground truth.\n"
      "Absolute trajectory error (ATE, after closed-form alignment of the estimate onto the "
      "ground truth)\nand relative pose error (RPE over a fixed delta), computed as TUM's "
      "evaluate_ate.py and\nevaluate_rpe.py --fixed_delta do. Both files are TUM trajectories: "
      "timestamp tx ty tz qx qy qz qw\n(camera-to-world).");
  auto settings = std::make_shared<EvalSettings>();
  auto unit = std::make_shared<std::string>("s");
  auto json = std::make_shared<bool>(false);
  auto plot = std::make_shared<std::string>();
  app->add_option("--gt", settings->ground_truth_file, "ground-truth trajectory file")->required();
  app->add_option("--est", settings->estimate_file, "estimated trajectory file")->required();
  app->add_option("--max-dt", settings->ate.max_difference,
                  "max timestamp difference (s) for associating poses")
      ->check(in_range(1e-9, 1e9))
      ->capture_default_str();
  app->add_option("--offset", settings->ate.offset,
                  "time offset (s) added to the estimate's timestamps")
      ->check(in_range(-1e6, 1e6))
      ->capture_default_str();
  app->add_option("--gt-body-to-camera", settings->gt_body_to_camera_file,
                  "transform from the ground truth's body (motion-capture marker) to the camera: "
                  "'tx ty tz qx qy qz qw' or a 4x4 matrix; the ground truth is moved onto the "
                  "camera before comparing (default: none, as published numbers are)");
  app->add_flag("--sim3", settings->ate.sim3,
                "align with scale (Sim(3), monocular) instead of SE(3)");
  settings->rpe.delta = 1.0;
  app->add_option("--rpe-delta", settings->rpe.delta, "RPE pose distance, in --rpe-unit")
      ->check(in_range(1e-9, 1e9))
      ->capture_default_str();
  app->add_option("--rpe-unit", *unit, "unit of --rpe-delta: s (seconds) or f (frames)")
      ->check(CLI::IsMember({"s", "f"}))
      ->capture_default_str();
  app->add_flag("--json", *json, "print the results as JSON instead of a table");
  auto title = std::make_shared<std::string>();
  app->add_option("--plot", *plot,
                  "write plots (PNG and SVG) into this folder: trajectory top view coloured by "
                  "ATE, ATE, position, orientation and RPE over time");
  app->add_option("--title", *title,
                  "run name leading every plot title (default: '<sequence>, mode <mode>' from the "
                  "stats.json beside --est, as 'pspslam run' writes it)");
  return {app, [settings, unit, json, plot, title](const GlobalOptions&) {
            settings->rpe.offset = settings->ate.offset;
            settings->rpe.unit = *unit == "s" ? RpeDeltaUnit::seconds : RpeDeltaUnit::frames;
            return evaluate(*settings, *json, *plot, *title);
          }};
}

}  // namespace pspslam::cli
