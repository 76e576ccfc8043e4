#include "pspslam/session/people_log.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>

#include "pspslam/io/trajectory_io.h"
#include "pspslam/session/frame_log.h"
#include "pspslam/session/run_statistics.h"

namespace pspslam {
namespace {

std::map<long long, Pose> by_frame(const Trajectory& trajectory) {
  std::map<long long, Pose> poses;
  for (const StampedPose& pose : trajectory)
    poses[std::llround(pose.timestamp * 1e6)] = pose.T_world_camera;
  return poses;
}

nlohmann::ordered_json score_json(const PeopleScore& score) {
  const auto percent = [](int part, int whole) {
    return whole > 0 ? 100.0 * static_cast<double>(part) / whole : 0.0;
  };
  return {{"person_frames", score.person_frames},
          {"tracked", score.tracked},
          {"tracked_percent", percent(score.tracked, score.person_frames)},
          {"missed", score.person_frames - score.tracked},
          {"reported", score.reported},
          {"false_reports", score.false_reports},
          {"false_percent", percent(score.false_reports, score.reported)},
          {"id_switches", score.id_switches},
          {"person_minutes", score.person_minutes},
          {"id_switches_per_person_minute",
           score.person_minutes > 0.0 ? score.id_switches / score.person_minutes : 0.0},
          {"position_error_mm_median", 1000.0 * score.median_position_error_m},
          {"position_error_mm_p90", 1000.0 * score.p90_position_error_m},
          {"floor_error_mm_median", 1000.0 * score.median_horizontal_error_m},
          {"velocity_error_mm_per_s_median", 1000.0 * score.median_velocity_error_mps},
          {"distinct_ids", score.distinct_ids}};
}

}  // namespace

PeopleLog::PeopleLog(const std::filesystem::path& folder)
    : file_(folder / "people.csv"), out_(open_output(file_)) {
  out_ << "frame,timestamp,id,x,y,z,vx,vy,vz,extent,visible_pixels\n";
}

void PeopleLog::write(size_t frame_index, Timestamp timestamp, const PeopleFrame& frame) {
  cpu_ms_.push_back(frame.cpu_ms);
  if (frame.observed) ++observed_frames_;
  char line[256];
  for (const TrackedPerson& person : frame.people) {
    std::snprintf(line, sizeof(line), "%zu,%.6f,%d,%.4f,%.4f,%.4f,%.3f,%.3f,%.3f,%.3f,%d\n",
                  frame_index, timestamp, person.id, person.position.x(), person.position.y(),
                  person.position.z(), person.velocity.x(), person.velocity.y(),
                  person.velocity.z(), person.extent_m, person.visible_pixels);
    out_ << line;
    rows_.push_back({timestamp, person});
    max_id_ = std::max(max_id_, person.id);
    ++written_rows_;
  }
  out_.flush();
}

nlohmann::ordered_json PeopleLog::summary(const std::filesystem::path& sequence,
                                          const std::optional<Trajectory>& ground_truth,
                                          const Trajectory& estimate) const {
  nlohmann::ordered_json json = {{"file", file_.filename().string()},
                                 {"tracks", max_id_},
                                 {"rows", written_rows_},
                                 {"frames_with_fresh_mask", observed_frames_},
                                 {"cpu_ms", to_json(summarize(cpu_ms_))}};
  const std::filesystem::path truth_file = sequence / "people.txt";
  if (sequence.empty() || !ground_truth || !std::filesystem::is_regular_file(truth_file))
    return json;
  Trajectory cameras = *ground_truth;
  if (std::filesystem::is_regular_file(sequence / "body_to_camera.txt"))
    cameras = body_to_camera(cameras, read_rigid_transform(sequence / "body_to_camera.txt"));
  const std::map<long long, Pose> truth_poses = by_frame(cameras);
  const std::map<long long, Pose> estimated = by_frame(estimate);
  const auto truth_from_estimate = [&](Timestamp t) -> std::optional<Pose> {
    const long long key = std::llround(t * 1e6);
    const auto truth = truth_poses.find(key);
    const auto est = estimated.find(key);
    if (truth == truth_poses.end() || est == estimated.end()) return std::nullopt;
    return truth->second * est->second.inverse();
  };
  json["score"] =
      score_json(score_people(read_people_truth(truth_file), rows_, truth_from_estimate));
  json["score"]["truth"] = truth_file.string();
  return json;
}

}  // namespace pspslam
