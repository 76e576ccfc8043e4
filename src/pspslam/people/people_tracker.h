#pragma once

#include <Eigen/Core>
#include <span>
#include <vector>

#include "pspslam/core/types.h"
#include "pspslam/people/person_detector.h"

namespace pspslam {

struct PeopleTrackerParams {
  // How fast a person changes velocity (white-noise acceleration of the constant-velocity
  // filter), m/s^2, and how far an observed centre lies from the true one, m.
  double acceleration_sigma = 1.0;
  double observation_sigma_m = 0.08;
  // An observation joins a track when it lies within gate_m plus twice the predicted position's
  // standard deviation of the prediction, at most max_gate_m (a person after an occlusion).
  double gate_m = 0.5;
  double max_gate_m = 1.2;
  // A new track gets an id after this many observations (a one-frame false mask gets none).
  int confirm_hits = 3;
  // A track unseen this long ends; before that, a person who reappears near the prediction
  // keeps her id (re-identification after a short occlusion). Unconfirmed tracks end sooner.
  double max_unseen_s = 1.5;
  double tentative_unseen_s = 0.2;
};

// One person's track at one frame, in the world frame.
struct TrackedPerson {
  int id = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // filtered centre, metres
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // m/s
  double extent_m = 0.0;
  int visible_pixels = 0;  // 0: predicted only (not seen in this frame)
};

// Links person observations over frames into tracks with stable ids: a constant-velocity
// Kalman filter per person (the three axes share one 2x2 covariance), gating around each
// prediction, greedy nearest-first association, coasting through short occlusions.
class PeopleTracker {
 public:
  explicit PeopleTracker(PeopleTrackerParams params = {}) : params_(params) {}

  // Moves every track to `timestamp`, joins the observations and returns the confirmed tracks
  // seen in this frame. With no observations (no fresh mask, no pose) tracks only coast.
  std::vector<TrackedPerson> update(Timestamp timestamp,
                                    std::span<const PersonObservation> observations);
  // Every confirmed track still alive, predicted to `timestamp` (visible_pixels 0).
  std::vector<TrackedPerson> predicted(Timestamp timestamp) const;

  int ids_issued() const { return next_id_ - 1; }
  const PeopleTrackerParams& params() const { return params_; }

 private:
  struct Track {
    int id = 0;  // 0 until confirmed
    int hits = 0;
    Eigen::Vector3d position, velocity;
    Eigen::Matrix2d covariance;  // of (position, velocity) along each axis
    Timestamp time = 0.0;        // of the state
    Timestamp last_seen = 0.0;
    double extent_m = 0.0;
  };
  void predict(Track& track, Timestamp timestamp) const;
  void correct(Track& track, const PersonObservation& observation) const;
  double gate(const Track& track) const;

  PeopleTrackerParams params_;
  std::vector<Track> tracks_;
  int next_id_ = 1;
};

}  // namespace pspslam
