#pragma once

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/people/people_score.h"
#include "pspslam/people/people_tracking.h"

namespace pspslam {

// OUT/people.csv (one row per tracked person and frame: frame, timestamp, id, position and
// velocity in the map's world frame, extent, visible pixels) and the `people` section of
// stats.json. Created only for runs that track people (System::tracks_people()).
class PeopleLog {
 public:
  explicit PeopleLog(const std::filesystem::path& folder);

  void write(size_t frame_index, Timestamp timestamp, const PeopleFrame& frame);
  // A new map replaced the world frame: earlier rows are not scored against the truth.
  void forget_rows() { rows_.clear(); }

  // stats.json "people": tracks, rows, per-frame CPU time; with a sequence's people.txt (and
  // ground truth) also the score of score_people(). `sequence`: the sequence folder (may be
  // empty); `estimate`: the run's online poses (trajectory.txt).
  nlohmann::ordered_json summary(const std::filesystem::path& sequence,
                                 const std::optional<Trajectory>& ground_truth,
                                 const Trajectory& estimate) const;

 private:
  std::filesystem::path file_;
  std::ofstream out_;
  std::vector<PersonEstimate> rows_;
  std::vector<double> cpu_ms_;
  size_t observed_frames_ = 0;
  size_t written_rows_ = 0;
  int max_id_ = 0;
};

}  // namespace pspslam
