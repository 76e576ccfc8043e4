#pragma once

#include <cstddef>
#include <memory>

namespace pspslam {

class KeyFrame;

// What tracking needs from local mapping (mapping/ comes after tracking in the module order,
// so tracking talks to it through this interface; System connects the two).
//
// Contract: a keyframe handed to insert_keyframe() is already complete in the Map — added to
// it, observed by all its map points (descriptors and normals updated), covisibility and
// spanning tree updated. Points created from its depth have first_keyframe_id == its id (the
// "recently added" points local mapping may cull). Local mapping triangulates, fuses, culls,
// and runs local BA; it does not need to register the keyframe again.
class KeyFrameSink {
 public:
  virtual ~KeyFrameSink() = default;
  virtual void insert_keyframe(std::shared_ptr<KeyFrame> keyframe) = 0;
  // True while idle (not processing a keyframe): a keyframe can be inserted without delay.
  virtual bool accepts_keyframes() const = 0;
  virtual size_t queued_keyframes() const = 0;
  // Asks a running local BA to stop early because a new keyframe is wanted.
  virtual void interrupt_bundle_adjustment() = 0;
};

}  // namespace pspslam
