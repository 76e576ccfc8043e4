#include "pspslam/eval/report.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <sstream>

namespace pspslam {
namespace {

std::string fixed(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

std::string short_number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%g", value);
  return buffer;
}

nlohmann::ordered_json to_json(const ErrorStats& s) {
  // Non-finite values (an undetermined statistic) are written as null by the library.
  return {{"count", s.count}, {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
          {"std", s.std},     {"min", s.min},   {"max", s.max}};
}

std::string table_row(const std::string& name, const std::string& unit, const ErrorStats& s,
                      int decimals) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), "  %-22s %-6s %6zu %10s %10s %10s %10s %10s %10s\n",
                name.c_str(), unit.c_str(), s.count, fixed(s.rmse, decimals).c_str(),
                fixed(s.mean, decimals).c_str(), fixed(s.median, decimals).c_str(),
                fixed(s.std, decimals).c_str(), fixed(s.min, decimals).c_str(),
                fixed(s.max, decimals).c_str());
  return buffer;
}

}  // namespace

std::string format_eval_table(const EvalSettings& settings, const AteResult& ate,
                              const RpeResult& rpe) {
  std::ostringstream out;
  out << "ground truth: " << settings.ground_truth_file
      << (settings.gt_body_to_camera_file.empty()
              ? std::string()
              : " (moved to the camera by " + settings.gt_body_to_camera_file + ")")
      << "\n";
  out << "estimate:     " << settings.estimate_file << "\n";
  out << "association:  max dt " << short_number(settings.ate.max_difference) << " s, offset "
      << short_number(settings.ate.offset) << " s\n";
  out << "alignment:    " << (settings.ate.sim3 ? "Sim(3)" : "SE(3)")
      << (settings.alignment_reason.empty() ? "" : " (" + settings.alignment_reason + ")")
      << ", scale " << fixed(ate.alignment.scale, 6) << "\n";
  out << "RPE delta:    " << short_number(settings.rpe.delta) << " "
      << (settings.rpe.unit == RpeDeltaUnit::seconds ? "s" : "frames") << "\n\n";
  char header[256];
  std::snprintf(header, sizeof(header), "  %-22s %-6s %6s %10s %10s %10s %10s %10s %10s\n",
                "metric", "unit", "pairs", "rmse", "mean", "median", "std", "min", "max");
  out << header;
  out << table_row("ATE", "m", ate.error, 4);
  out << table_row("RPE translation", "m", rpe.translation, 4);
  out << table_row("RPE translation rate", "m/s", rpe.translation_per_second, 4);
  out << table_row("RPE rotation", "deg", rpe.rotation, 3);
  out << table_row("RPE rotation rate", "deg/s", rpe.rotation_per_second, 3);
  if (rpe.body_frames_differ()) {
    out << "\nwarning: the ground truth's body frame is rotated "
        << fixed(rpe.body_frame_rotation_deg, 0)
        << " deg from the estimate's\n"
           "         (from the pairs' relative rotations): it tracks another body than the camera\n"
           "         (e.g. motion-capture markers), so the RPE rows compare motions expressed in\n"
           "         different frames and mean nothing; the ATE (positions only) is valid.\n";
  }
  return out.str();
}

std::string format_eval_json(const EvalSettings& settings, const AteResult& ate,
                             const RpeResult& rpe) {
  // Doubles are written in the shortest form that reads back bit for bit, so the numbers
  // compare exactly with other tools.
  const nlohmann::ordered_json report = {
      {"ground_truth", settings.ground_truth_file},
      {"estimate", settings.estimate_file},
      {"gt_body_to_camera", settings.gt_body_to_camera_file.empty()
                                ? nlohmann::ordered_json(nullptr)
                                : nlohmann::ordered_json(settings.gt_body_to_camera_file)},
      {"ate",
       {{"alignment", settings.ate.sim3 ? "sim3" : "se3"},
        {"alignment_reason", settings.alignment_reason},
        {"max_dt_s", settings.ate.max_difference},
        {"offset_s", settings.ate.offset},
        {"scale", ate.alignment.scale},
        {"error_m", to_json(ate.error)}}},
      {"rpe",
       {{"delta", settings.rpe.delta},
        {"delta_unit", to_string(settings.rpe.unit)},
        {"translation_m", to_json(rpe.translation)},
        {"translation_m_per_s", to_json(rpe.translation_per_second)},
        {"rotation_deg", to_json(rpe.rotation)},
        {"rotation_deg_per_s", to_json(rpe.rotation_per_second)},
        {"body_frame_rotation_deg", rpe.body_frame_rotation_deg},
        {"body_frames_differ", rpe.body_frames_differ()}}}};
  return report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace pspslam
