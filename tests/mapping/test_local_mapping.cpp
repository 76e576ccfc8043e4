#include "pspslam/mapping/local_mapping.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "mapping/synthetic_world.h"

namespace pspslam {
namespace {

using namespace std::chrono_literals;
using testing::SyntheticWorld;

TEST(LocalMapping, ProcessesInsertedKeyframesOnItsThread) {
  SyntheticWorld world(500, 0.3, 31);
  auto map = std::make_shared<Map>();
  LocalMapping mapping(map);
  for (int k = 0; k < 5; ++k) {
    const Pose pose = testing::path_pose(k);
    mapping.insert_keyframe(world.make_keyframe(k, pose, pose, *map));
    mapping.wait_until_idle();  // the next keyframe's "tracking" needs this one's points
  }
  const LocalMappingStats stats = mapping.stats();
  EXPECT_EQ(stats.keyframes_processed, 5u);
  EXPECT_GT(stats.points_triangulated, 0u);
  EXPECT_GE(stats.bundle_adjustments, 3u);
  EXPECT_EQ(mapping.queue_size(), 0u);
  EXPECT_TRUE(mapping.accepts_keyframes());
  EXPECT_GE(map->num_keyframes(), 2u);
  EXPECT_GT(map->num_map_points(), 100u);
}

TEST(LocalMapping, ShutdownWithQueuedKeyframesIsClean) {
  SyntheticWorld world(500, 0.3, 32);
  auto map = std::make_shared<Map>();
  std::vector<std::shared_ptr<KeyFrame>> keyframes;
  for (int k = 0; k < 12; ++k) {
    const Pose pose = testing::path_pose(k);
    keyframes.push_back(world.make_keyframe(k, pose, pose, *map));
  }
  const auto start = std::chrono::steady_clock::now();
  {
    LocalMapping mapping(map);
    for (auto& keyframe : keyframes) mapping.insert_keyframe(keyframe);
    EXPECT_GT(mapping.queue_size(), 0u);
  }  // destroyed with work pending: interrupts, drops the queue, joins
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
  EXPECT_LT(map->num_keyframes(), keyframes.size());
  for (const auto& point : map->map_points()) EXPECT_FALSE(point->is_bad());
}

TEST(LocalMapping, StopHoldsKeyframesUntilRelease) {
  SyntheticWorld world(300, 0.0, 33);
  auto map = std::make_shared<Map>();
  LocalMapping mapping(map);
  mapping.request_stop();
  const auto deadline = std::chrono::steady_clock::now() + 2s;
  while (!mapping.is_stopped() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(1ms);
  }
  ASSERT_TRUE(mapping.is_stopped());
  EXPECT_FALSE(mapping.accepts_keyframes());

  const Pose pose = testing::path_pose(0);
  mapping.insert_keyframe(world.make_keyframe(0, pose, pose, *map));
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(mapping.queue_size(), 1u);
  EXPECT_EQ(mapping.stats().keyframes_processed, 0u);

  mapping.release();
  mapping.wait_until_idle();
  EXPECT_FALSE(mapping.is_stopped());
  EXPECT_EQ(mapping.stats().keyframes_processed, 1u);
  EXPECT_EQ(map->num_keyframes(), 1u);
}

}  // namespace
}  // namespace pspslam
