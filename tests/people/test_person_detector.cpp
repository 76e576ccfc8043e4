#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "pspslam/people/person_detector.h"

namespace pspslam {
namespace {

constexpr int kPerson = 15;

PinholeCamera camera() { return PinholeCamera{}; }  // 640x480, f 525, centre (319.5, 239.5)

// A wall 5 m away; each person a rectangle of label 15 at one depth.
struct Scene {
  cv::Mat labels = cv::Mat(480, 640, CV_8UC1, cv::Scalar(0));
  cv::Mat depth = cv::Mat(480, 640, CV_32FC1, cv::Scalar(5.0f));
  void person(const cv::Rect& box, float z) {
    labels(box).setTo(kPerson);
    depth(box).setTo(z);
  }
};

// Where the detector should put a rectangle's person: its centre pixel's ray, 0.15 m behind.
Eigen::Vector3d expected_centre(const cv::Rect& box, double z) {
  const PinholeCamera cam = camera();
  const Eigen::Vector3d ray =
      cam.unproject(Eigen::Vector2d(box.x + box.width / 2.0, box.y + box.height / 2.0), 1.0)
          .normalized();
  return ray * (z / ray.z() + 0.15);
}

TEST(PersonDetector, TwoPeopleAtDifferentDepthsAreTwoInstancesEvenWhereTheyOverlap) {
  Scene scene;
  const cv::Rect far(300, 100, 80, 240), near(200, 80, 140, 380);
  scene.person(far, 3.0f);
  scene.person(near, 1.5f);  // covers the left part of the far person
  PersonDetector detector;
  const std::vector<PersonObservation> people =
      detector.detect(scene.labels, kPerson, scene.depth, camera(), Pose::Identity());
  ASSERT_EQ(people.size(), 2u);
  // Largest first: the near person.
  EXPECT_LT((people[0].position_camera - expected_centre(near, 1.5)).norm(), 0.03);
  const cv::Rect far_visible(340, 100, 40, 240);
  EXPECT_LT((people[1].position_camera - expected_centre(far_visible, 3.0)).norm(), 0.05);
  EXPECT_NEAR(people[0].visible_pixels, 140 * 380, 140 * 380 * 0.05);
  EXPECT_NEAR(people[0].extent_m, 380 * 0.8 * 1.5 / 525.0, 0.1);
}

TEST(PersonDetector, AnArmCutOffByItsDepthJumpJoinsItsBody) {
  Scene scene;
  scene.person(cv::Rect(280, 120, 80, 300), 2.0f);
  scene.person(cv::Rect(360, 200, 32, 100), 1.7f);  // the arm, 0.3 m in front of the torso
  PersonDetector detector;
  const std::vector<PersonObservation> people =
      detector.detect(scene.labels, kPerson, scene.depth, camera(), Pose::Identity());
  ASSERT_EQ(people.size(), 1u);
  EXPECT_EQ(people[0].box, cv::Rect(280, 120, 112, 300));
}

TEST(PersonDetector, OtherClassesNoDepthAndSmallFragmentsAreNotPeople) {
  Scene scene;
  scene.labels(cv::Rect(100, 100, 100, 200)).setTo(7);  // a car
  scene.person(cv::Rect(400, 100, 80, 200), 2.0f);
  scene.depth(cv::Rect(400, 100, 80, 200)).setTo(0.0f);  // no depth on the person
  scene.person(cv::Rect(10, 10, 12, 12), 2.0f);          // 144 pixels
  PersonDetector detector;
  EXPECT_TRUE(
      detector.detect(scene.labels, kPerson, scene.depth, camera(), Pose::Identity()).empty());
}

TEST(PersonDetector, APersonPaintedOnTheWallIsNotAPerson) {
  Scene scene;
  scene.labels(cv::Rect(100, 100, 120, 240)).setTo(kPerson);  // at the wall's depth
  scene.person(cv::Rect(400, 100, 80, 240), 2.0f);            // in front of it
  PersonDetector detector;
  const std::vector<PersonObservation> people =
      detector.detect(scene.labels, kPerson, scene.depth, camera(), Pose::Identity());
  ASSERT_EQ(people.size(), 1u);
  EXPECT_GT(people[0].position_camera.x(), 0.0);
}

TEST(PersonDetector, CentresAreMovedIntoTheWorldByTheCameraPose) {
  Scene scene;
  const cv::Rect box(280, 120, 80, 240);
  scene.person(box, 2.0f);
  Pose T_world_camera = Pose::Identity();
  T_world_camera.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T_world_camera.translation() = Eigen::Vector3d(1.0, -2.0, 0.5);
  PersonDetector detector;
  const std::vector<PersonObservation> people =
      detector.detect(scene.labels, kPerson, scene.depth, camera(), T_world_camera);
  ASSERT_EQ(people.size(), 1u);
  EXPECT_LT((people[0].position_world - T_world_camera * expected_centre(box, 2.0)).norm(), 0.03);
}

TEST(PersonDetector, LabelsOfAnotherSizeAreReadAtTheScaledPixel) {
  Scene scene;
  const cv::Rect box(280, 120, 80, 240);
  scene.person(box, 2.0f);
  cv::Mat half_labels(240, 320, CV_8UC1, cv::Scalar(0));
  half_labels(cv::Rect(140, 60, 40, 120)).setTo(kPerson);
  PersonDetector detector;
  const std::vector<PersonObservation> people =
      detector.detect(half_labels, kPerson, scene.depth, camera(), Pose::Identity());
  ASSERT_EQ(people.size(), 1u);
  EXPECT_LT((people[0].position_camera - expected_centre(box, 2.0)).norm(), 0.03);
}

}  // namespace
}  // namespace pspslam
