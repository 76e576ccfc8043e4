#include "pspslam/people/people_tracker.h"

#include <algorithm>
#include <cmath>
#include <tuple>

namespace pspslam {

void PeopleTracker::predict(Track& track, Timestamp timestamp) const {
  const double dt = timestamp - track.time;
  if (dt <= 0.0) return;
  track.position += dt * track.velocity;
  Eigen::Matrix2d F;
  F << 1.0, dt, 0.0, 1.0;
  const double q = params_.acceleration_sigma * params_.acceleration_sigma;
  Eigen::Matrix2d Q;
  Q << dt * dt * dt * dt / 4.0, dt * dt * dt / 2.0, dt * dt * dt / 2.0, dt * dt;
  track.covariance = F * track.covariance * F.transpose() + q * Q;
  track.time = timestamp;
}

void PeopleTracker::correct(Track& track, const PersonObservation& observation) const {
  const double r = params_.observation_sigma_m * params_.observation_sigma_m;
  const Eigen::Matrix2d& P = track.covariance;
  const double s = P(0, 0) + r;
  const Eigen::Vector2d gain(P(0, 0) / s, P(1, 0) / s);
  const Eigen::Vector3d innovation = observation.position_world - track.position;
  track.position += gain(0) * innovation;
  track.velocity += gain(1) * innovation;
  Eigen::Matrix2d I_KH = Eigen::Matrix2d::Identity();
  I_KH(0, 0) -= gain(0);
  I_KH(1, 0) -= gain(1);
  track.covariance = I_KH * P;
  track.extent_m = observation.extent_m;
  track.last_seen = track.time;
  ++track.hits;
}

double PeopleTracker::gate(const Track& track) const {
  return std::min(params_.max_gate_m, params_.gate_m + 2.0 * std::sqrt(track.covariance(0, 0)));
}

std::vector<TrackedPerson> PeopleTracker::update(Timestamp timestamp,
                                                 std::span<const PersonObservation> observations) {
  for (Track& track : tracks_) predict(track, timestamp);
  // Every pair within its track's gate, nearest first; each track and observation joins once.
  std::vector<std::tuple<double, size_t, size_t>> pairs;
  for (size_t t = 0; t < tracks_.size(); ++t) {
    for (size_t o = 0; o < observations.size(); ++o) {
      const double distance = (observations[o].position_world - tracks_[t].position).norm();
      if (distance <= gate(tracks_[t])) pairs.emplace_back(distance, t, o);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<int> observation_of(tracks_.size(), -1);
  std::vector<bool> used(observations.size(), false);
  for (const auto& [distance, t, o] : pairs) {
    if (observation_of[t] >= 0 || used[o]) continue;
    observation_of[t] = static_cast<int>(o);
    used[o] = true;
  }
  std::vector<TrackedPerson> seen;
  for (size_t t = 0; t < tracks_.size(); ++t) {
    if (observation_of[t] < 0) continue;
    Track& track = tracks_[t];
    const PersonObservation& observation = observations[static_cast<size_t>(observation_of[t])];
    correct(track, observation);
    if (track.id == 0 && track.hits >= params_.confirm_hits) track.id = next_id_++;
    if (track.id > 0) {
      seen.push_back(
          {track.id, track.position, track.velocity, track.extent_m, observation.visible_pixels});
    }
  }
  std::erase_if(tracks_, [&](const Track& track) {
    const double unseen = timestamp - track.last_seen;
    return unseen > (track.id > 0 ? params_.max_unseen_s : params_.tentative_unseen_s);
  });
  const double r = params_.observation_sigma_m * params_.observation_sigma_m;
  for (size_t o = 0; o < observations.size(); ++o) {
    if (used[o]) continue;
    Track track;
    track.hits = 1;
    track.position = observations[o].position_world;
    track.velocity.setZero();
    track.covariance << r, 0.0, 0.0, 1.0;  // a person walks at about 1 m/s, direction unknown
    track.time = track.last_seen = timestamp;
    track.extent_m = observations[o].extent_m;
    tracks_.push_back(track);
  }
  std::sort(seen.begin(), seen.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  return seen;
}

std::vector<TrackedPerson> PeopleTracker::predicted(Timestamp timestamp) const {
  std::vector<TrackedPerson> people;
  for (const Track& track : tracks_) {
    if (track.id == 0) continue;
    const double dt = std::max(0.0, timestamp - track.time);
    people.push_back(
        {track.id, track.position + dt * track.velocity, track.velocity, track.extent_m, 0});
  }
  return people;
}

}  // namespace pspslam
