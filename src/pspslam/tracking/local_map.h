#pragma once

#include <cstdint>
#include <memory>
#include <vector>

namespace pspslam {

class Frame;
class KeyFrame;
class MapPoint;

// The neighbourhood of the map that tracking matches a frame against (ORB-SLAM2's local map):
// the keyframes that observe the frame's matched points, their best covisible keyframes,
// children and parents, and every map point those keyframes observe. Buffers are reused from
// frame to frame.
class LocalMap {
 public:
  explicit LocalMap(size_t max_keyframes = 80) : max_keyframes_(max_keyframes) {}

  // Rebuilds the local keyframes and points for `frame`; returns the keyframe sharing the most
  // points with the frame (the new reference keyframe), nullptr if none.
  std::shared_ptr<KeyFrame> update(const Frame& frame);

  const std::vector<std::shared_ptr<KeyFrame>>& keyframes() const { return keyframes_; }
  const std::vector<std::shared_ptr<MapPoint>>& points() const { return points_; }

 private:
  void add_keyframe(const std::shared_ptr<KeyFrame>& keyframe, std::uint64_t frame_id);

  size_t max_keyframes_;
  std::vector<std::shared_ptr<KeyFrame>> keyframes_;
  std::vector<std::shared_ptr<MapPoint>> points_;
  std::vector<std::pair<std::shared_ptr<KeyFrame>, int>> counts_;
};

}  // namespace pspslam
