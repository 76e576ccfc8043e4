#include "pspslam/core/similarity.h"

#include <gtest/gtest.h>

namespace pspslam {
namespace {

Sim3 example(double scale) {
  return {Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, -2.0, 0.5).normalized()).toRotationMatrix(),
          Eigen::Vector3d(0.3, -1.2, 2.0), scale};
}

TEST(Sim3, ComposesInvertsAndActsOnPoints) {
  const Sim3 a = example(1.7);
  const Sim3 b(Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitY()).toRotationMatrix(),
               Eigen::Vector3d(-0.5, 0.1, 0.9), 0.6);
  const Eigen::Vector3d p(0.25, -0.8, 3.1);
  EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-12);
  EXPECT_NEAR((a * b).scale, 1.7 * 0.6, 1e-15);
  EXPECT_LT((a.inverse() * (a * p) - p).norm(), 1e-12);
  const Sim3 identity = a * a.inverse();
  EXPECT_NEAR(identity.scale, 1.0, 1e-15);
  EXPECT_LT((identity.rotation - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_LT(identity.translation.norm(), 1e-12);
  // A rigid pose is a similarity of scale 1 acting the same way.
  Pose rigid = Pose::Identity();
  rigid.linear() = b.rotation;
  rigid.translation() = b.translation;
  EXPECT_LT((Sim3(rigid) * p - rigid * p).norm(), 1e-15);
  EXPECT_LT(((a * rigid) * p - a * (rigid * p)).norm(), 1e-12);
}

// The rescaled pose stands for S_camera_world in the camera's own units: same ray for every
// point (so the same pixel), depth divided by the scale.
TEST(Sim3, RescaledPoseProjectsLikeTheSimilarity) {
  const Sim3 S = example(0.4);
  const Pose pose = S.rescaled_pose();
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(1.0, 2.0, 9.0), Eigen::Vector3d(-3.0, 0.5, 6.0),
                                   Eigen::Vector3d(0.0, 0.0, 0.0)}) {
    const Eigen::Vector3d by_similarity = S * p;
    const Eigen::Vector3d by_pose = pose * p;
    EXPECT_LT((by_similarity - S.scale * by_pose).norm(), 1e-12);
  }
  // Its camera centre is where the similarity sends the camera's origin back to.
  EXPECT_LT((pose.inverse().translation() - S.inverse() * Eigen::Vector3d::Zero()).norm(), 1e-12);
}

}  // namespace
}  // namespace pspslam
