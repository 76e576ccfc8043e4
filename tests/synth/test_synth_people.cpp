#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "pspslam/synth/people_truth.h"
#include "pspslam/synth/scene.h"

namespace pspslam {
namespace {

TEST(SynthPeopleTruth, EveryPersonPixelBelongsToOnePersonWhoWalksInFrontOfHerPixels) {
  SynthOptions options;
  options.frames = 120;
  options.bodies = 3;
  options.seed = 2;
  options.threads = 2;
  const SyntheticScene scene(options);
  SynthFrame frame;
  int frames_with_people = 0;
  for (size_t index = 0; index < scene.frame_count(); index += 10) {
    scene.render(index, frame, 2);
    const std::vector<PersonTruth> people = people_truth(scene, frame);
    ASSERT_EQ(people.size(), 3u);
    int pixels = 0;
    for (const PersonTruth& person : people) {
      EXPECT_EQ(person.id, &person - people.data());
      EXPECT_DOUBLE_EQ(person.timestamp, frame.timestamp);
      pixels += person.visible_pixels;
      // Inside the room, torso centre about 1.16 m up, walking at human speed on the floor.
      EXPECT_GT(person.position.z(), 0.9);
      EXPECT_LT(person.position.z(), 1.5);
      EXPECT_GT(person.velocity.head<2>().norm(), 0.3);
      EXPECT_LT(person.velocity.head<2>().norm(), 2.0);
      EXPECT_LT(std::abs(person.velocity.z()), 0.2);
      if (person.visible_pixels < 2000) continue;
      // A visible person's centre lies in front of the camera, within the image.
      const Eigen::Vector3d in_camera = frame.T_world_camera.inverse() * person.position;
      EXPECT_GT(in_camera.z(), 0.2);
    }
    EXPECT_EQ(pixels, cv::countNonZero(frame.labels == kSynthLabelPerson)) << "frame " << index;
    frames_with_people += pixels > 0;
  }
  EXPECT_GE(frames_with_people, 3);
}

}  // namespace
}  // namespace pspslam
