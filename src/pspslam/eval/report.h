#pragma once

#include <string>

#include "pspslam/eval/ate.h"
#include "pspslam/eval/rpe.h"

namespace pspslam {

// What was evaluated and how, echoed in reports so a result is never separated from its settings.
struct EvalSettings {
  std::string ground_truth_file;
  std::string estimate_file;
  // --gt-body-to-camera: file of the transform from the ground truth's body (a motion-capture
  // marker) to the camera; empty: the ground truth is taken as the camera's pose.
  std::string gt_body_to_camera_file;
  AteOptions ate;
  RpeOptions rpe;
  // Why ate.sim3 is what it is, printed beside the alignment: "--sim3", or the run's stats.json
  // saying monocular (`pspslam eval` turns Sim(3) on then); empty: the default, SE(3).
  std::string alignment_reason;
};

// Human-readable ATE/RPE table (fixed-width, units in every row).
std::string format_eval_table(const EvalSettings& settings, const AteResult& ate,
                              const RpeResult& rpe);

// The same numbers as one JSON object (numbers printed with 17 significant digits so they
// compare bit-for-bit with other tools; non-finite values as null).
std::string format_eval_json(const EvalSettings& settings, const AteResult& ate,
                             const RpeResult& rpe);

}  // namespace pspslam
