#include <gtest/gtest.h>

#include <vector>

#include "pspslam/people/people_tracker.h"

namespace pspslam {
namespace {

constexpr double kPeriod = 1.0 / 30.0;

PersonObservation seen_at(const Eigen::Vector3d& position) {
  PersonObservation observation;
  observation.position_world = position;
  observation.extent_m = 1.7;
  observation.visible_pixels = 5000;
  return observation;
}

// Small deterministic jitter of an observed centre (limbs, the visible part changing).
Eigen::Vector3d jitter(int frame, int person) {
  const double a = 0.03 * std::sin(1.7 * frame + person), b = 0.03 * std::cos(2.3 * frame - person);
  return Eigen::Vector3d(a, b, 0.5 * a);
}

TEST(PeopleTracker, TwoWalkersKeepTheirIdsAndTheirVelocitiesAreMeasured) {
  PeopleTracker tracker;
  const Eigen::Vector3d velocity_a(1.0, 0.0, 0.0), velocity_b(0.0, -0.8, 0.0);
  std::vector<TrackedPerson> last;
  std::vector<int> ids_of_a;
  for (int frame = 0; frame < 90; ++frame) {
    const double t = frame * kPeriod;
    const std::vector<PersonObservation> observations = {
        seen_at(Eigen::Vector3d(0, 0, 0) + t * velocity_a + jitter(frame, 0)),
        seen_at(Eigen::Vector3d(1.5, 2.0, 0) + t * velocity_b + jitter(frame, 1))};
    last = tracker.update(t, observations);
    if (frame < 2) {
      EXPECT_TRUE(last.empty()) << "unconfirmed at frame " << frame;
    }
  }
  ASSERT_EQ(last.size(), 2u);
  EXPECT_EQ(last[0].id, 1);
  EXPECT_EQ(last[1].id, 2);
  EXPECT_EQ(tracker.ids_issued(), 2);
  const double t = 89 * kPeriod;
  EXPECT_LT((last[0].position - t * velocity_a).norm(), 0.06);
  EXPECT_LT((last[0].velocity - velocity_a).norm(), 0.2);
  EXPECT_LT((last[1].velocity - velocity_b).norm(), 0.2);
  EXPECT_EQ(last[0].visible_pixels, 5000);
}

TEST(PeopleTracker, APersonHiddenForHalfASecondKeepsHerId) {
  PeopleTracker tracker;
  const Eigen::Vector3d velocity(1.2, 0.3, 0.0);
  int id = 0;
  for (int frame = 0; frame < 60; ++frame) {
    const double t = frame * kPeriod;
    const bool hidden = frame >= 30 && frame < 45;
    std::vector<PersonObservation> observations;
    if (!hidden) observations.push_back(seen_at(t * velocity + jitter(frame, 0)));
    const std::vector<TrackedPerson> people = tracker.update(t, observations);
    if (hidden) {
      EXPECT_TRUE(people.empty());
      ASSERT_EQ(tracker.predicted(t).size(), 1u);
      continue;
    }
    if (frame < 2) continue;
    ASSERT_EQ(people.size(), 1u) << "frame " << frame;
    if (id == 0) id = people[0].id;
    EXPECT_EQ(people[0].id, id) << "frame " << frame;
  }
  EXPECT_EQ(tracker.ids_issued(), 1);
}

TEST(PeopleTracker, AOneFrameFalseDetectionGetsNoIdAndATrackUnseenTooLongEnds) {
  PeopleTracker tracker;
  for (int frame = 0; frame < 10; ++frame) {
    std::vector<PersonObservation> observations = {seen_at(Eigen::Vector3d(0, 0, 0))};
    if (frame == 5) observations.push_back(seen_at(Eigen::Vector3d(3, 0, 0)));
    const std::vector<TrackedPerson> people = tracker.update(frame * kPeriod, observations);
    for (const TrackedPerson& person : people) EXPECT_EQ(person.id, 1);
  }
  EXPECT_EQ(tracker.ids_issued(), 1);
  // Unseen for longer than max_unseen_s: she is gone; seen again, she is someone new.
  EXPECT_TRUE(tracker.update(2.0, {}).empty());
  EXPECT_TRUE(tracker.predicted(2.0).empty());
  const std::vector<PersonObservation> back = {seen_at(Eigen::Vector3d(0, 0, 0))};
  for (int frame = 0; frame < 3; ++frame) tracker.update(2.0 + frame * kPeriod, back);
  EXPECT_EQ(tracker.ids_issued(), 2);
}

TEST(PeopleTracker, TwoPeoplePassingCloseDoNotSwapIds) {
  PeopleTracker tracker;
  // Head-on on parallel lines 0.6 m apart, at 1 m/s each.
  std::vector<TrackedPerson> people;
  for (int frame = 0; frame < 120; ++frame) {
    const double t = frame * kPeriod;
    const std::vector<PersonObservation> observations = {
        seen_at(Eigen::Vector3d(-2.0 + t, 0.0, 0.0) + jitter(frame, 0)),
        seen_at(Eigen::Vector3d(2.0 - t, 0.6, 0.0) + jitter(frame, 1))};
    people = tracker.update(t, observations);
  }
  ASSERT_EQ(people.size(), 2u);
  EXPECT_GT(people[0].velocity.x(), 0.8);  // id 1 is still the one walking +x
  EXPECT_LT(people[1].velocity.x(), -0.8);
  EXPECT_EQ(tracker.ids_issued(), 2);
}

}  // namespace
}  // namespace pspslam
