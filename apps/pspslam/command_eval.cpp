// `pspslam eval`: ATE and RPE of an estimated trajectory, as TUM's evaluate_ate.py /
// evaluate_rpe.py compute them; the numerics live in pspslam_eval.
#include <iostream>
#include <string>
#include <vector>

#include "commands.h"
#include "pspslam/core/arg_parser.h"
#include "pspslam/core/error.h"
#include "pspslam/eval/ate.h"
#include "pspslam/eval/plots.h"
#include "pspslam/eval/report.h"
#include "pspslam/eval/rpe.h"
#include "pspslam/io/trajectory_io.h"

namespace pspslam::cli {

int eval_command(const std::vector<std::string>& args) {
  ArgParser parser("pspslam eval",
                   "Absolute trajectory error (ATE, after closed-form alignment of the estimate "
                   "onto the ground truth)\nand relative pose error (RPE over a fixed delta), "
                   "computed as TUM's evaluate_ate.py and\nevaluate_rpe.py --fixed_delta do. "
                   "Both files are TUM trajectories: timestamp tx ty tz qx qy qz qw\n"
                   "(camera-to-world).");
  parser.add_option("gt", "ground-truth trajectory file", "", true);
  parser.add_option("est", "estimated trajectory file", "", true);
  parser.add_option("max-dt", "max timestamp difference (s) for associating poses", "0.02");
  parser.add_option("offset", "time offset (s) added to the estimate's timestamps", "0");
  parser.add_switch("sim3", "align with scale (Sim(3), monocular) instead of SE(3)");
  parser.add_option("rpe-delta", "RPE pose distance, in --rpe-unit", "1.0");
  parser.add_option("rpe-unit", "unit of --rpe-delta: s (seconds) or f (frames)", "s");
  parser.add_switch("json", "print the results as JSON instead of a table");
  parser.add_option("plot", "write trajectory and error plots (PNG and SVG) into this folder");
  if (!parser.parse(args)) return 0;

  EvalSettings settings;
  settings.ground_truth_file = parser.get("gt");
  settings.estimate_file = parser.get("est");
  settings.ate.max_difference = parser.get_double("max-dt");
  settings.ate.offset = parser.get_double("offset");
  settings.ate.sim3 = parser.flag("sim3");
  settings.rpe.delta = parser.get_double("rpe-delta");
  settings.rpe.offset = settings.ate.offset;
  const std::string unit = parser.get("rpe-unit");
  if (unit == "s") {
    settings.rpe.unit = RpeDeltaUnit::seconds;
  } else if (unit == "f") {
    settings.rpe.unit = RpeDeltaUnit::frames;
  } else {
    throw Error("pspslam eval: flag --rpe-unit expects 's' or 'f', got '" + unit + "'");
  }
  if (!(settings.ate.max_difference > 0.0)) {
    throw Error("pspslam eval: flag --max-dt must be > 0, got '" + parser.get("max-dt") + "'");
  }
  if (!(settings.rpe.delta > 0.0)) {
    throw Error("pspslam eval: flag --rpe-delta must be > 0, got '" + parser.get("rpe-delta") +
                "'");
  }

  const Trajectory ground_truth = read_tum_trajectory(settings.ground_truth_file);
  const Trajectory estimate = read_tum_trajectory(settings.estimate_file);
  if (estimate.empty()) throw Error(settings.estimate_file + ": trajectory has no pose");
  if (ground_truth.empty()) throw Error(settings.ground_truth_file + ": trajectory has no pose");
  const AteResult ate = compute_ate(ground_truth, estimate, settings.ate);
  const RpeResult rpe = compute_rpe(ground_truth, estimate, settings.rpe);

  std::cout << (parser.flag("json") ? format_eval_json(settings, ate, rpe)
                                    : format_eval_table(settings, ate, rpe));
  if (parser.has("plot")) {
    const AtePlotFiles files =
        write_ate_plots(ate, parser.get("plot"), settings.ate.sim3 ? "Sim(3)" : "SE(3)");
    // Keep stdout pure JSON under --json: the plot list goes to stderr.
    std::ostream& note = parser.flag("json") ? std::cerr : std::cout;
    note << "plots: " << files.trajectory_png.string() << " " << files.trajectory_svg.string()
         << " " << files.error_png.string() << " " << files.error_svg.string() << "\n";
  }
  return 0;
}

}  // namespace pspslam::cli
