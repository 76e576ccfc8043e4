#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <functional>
#include <optional>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/people/people_tracker.h"

namespace pspslam {

// One person at one frame as the synthetic scene knows her (`pspslam synth`: people.txt).
struct PersonTruth {
  Timestamp timestamp = 0.0;
  int id = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // torso centre, world, metres
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s
  int visible_pixels = 0;                              // person pixels in the colour image
};

// One track at one frame as a run reports it (people.csv).
struct PersonEstimate {
  Timestamp timestamp = 0.0;
  TrackedPerson person;
};

// people.txt: "# ..." comments, then per line `timestamp id x y z vx vy vz visible_pixels`.
// Throws pspslam::Error naming file:line on a malformed line.
std::vector<PersonTruth> read_people_truth(const std::filesystem::path& file);
void write_people_truth(const std::filesystem::path& file, const std::vector<PersonTruth>& rows);

struct PeopleScoreOptions {
  int min_visible_pixels = 2000;  // truth person-frames that must be tracked
  double match_distance_m = 0.5;  // a track this close to a visible person is hers
};

struct PeopleScore {
  int person_frames = 0;        // truth person-frames with at least min_visible_pixels
  int tracked = 0;              // of which a track matched
  int reported = 0;             // track-frames the run reported (on frames with a pose and truth)
  int false_reports = 0;        // of which no visible person matched
  int id_switches = 0;          // a person's matched track id changed
  double person_minutes = 0.0;  // of person-frames (frame period from the timestamps)
  double median_position_error_m = 0.0;  // 3D, matched track-frames
  double p90_position_error_m = 0.0;
  double median_horizontal_error_m = 0.0;  // in the truth's floor plane (z up)
  double median_velocity_error_mps = 0.0;
  int distinct_ids = 0;  // track ids the run reported
};

// Scores reported tracks against the truth. `truth_from_estimate(t)` maps the run's world into
// the truth's world at frame t (ground-truth camera pose times the inverse of the estimated
// one), so a pose error of the run does not count as a person's position error; frames it
// returns nothing for are not scored.
PeopleScore score_people(const std::vector<PersonTruth>& truth,
                         const std::vector<PersonEstimate>& estimates,
                         const std::function<std::optional<Pose>(Timestamp)>& truth_from_estimate,
                         const PeopleScoreOptions& options = {});

}  // namespace pspslam
