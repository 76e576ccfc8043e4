#pragma once

// Local mapping thread (ORB-SLAM2 LocalMapping): owns its worker thread and keyframe queue.
//
// Expected call pattern (tracking / System):
//   auto mapping = std::make_unique<LocalMapping>(map, config);   // thread starts here
//   // or LocalMapping(map, LocalMappingOptions{...}) to tune thresholds
//   // tracking, when it wants a new keyframe (ORB-SLAM2's RGB-D policy):
//   if (mapping->accepts_keyframes()) {
//     mapping->insert_keyframe(keyframe);
//   } else {
//     mapping->interrupt_bundle_adjustment();   // make the mapper free up soon
//     if (mapping->queue_size() < 3) mapping->insert_keyframe(keyframe);  // also interrupts BA
//   }
//   mapping->wait_until_idle();             // optional: deterministic offline runs / tests
//   mapping->request_stop(); ... is_stopped() ... mapping->release();   // e.g. loop closing
//   mapping.reset();   // joins; keyframes still queued are dropped (never half-processed)
//
// The keyframe passed in must have its map point associations set (KeyFrame constructor) and
// may or may not be in the Map yet: local mapping registers its observations, adds it to the
// Map, and creates points from its close depth readings. Points that tracking created for the
// keyframe should have first_keyframe_id == keyframe id so they get culled if they prove bad.
// Map changes are published under Map::update_mutex() only where several values must change
// together (BA write-back); everything else relies on the map classes' own locking.

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <stop_token>
#include <thread>
#include <utility>

#include "pspslam/mapping/local_mapper.h"
#include "pspslam/mapping/local_mapping_options.h"

namespace pspslam {

class KeyFrame;
class Map;
class PlaceRecognition;

class LocalMapping {
 public:
  // `place` (may be null): vocabulary + keyframe database that processed keyframes are added to
  // (see LocalMapper).
  explicit LocalMapping(std::shared_ptr<Map> map, LocalMappingOptions options = {},
                        std::shared_ptr<PlaceRecognition> place = nullptr);
  LocalMapping(std::shared_ptr<Map> map, const SystemConfig& config)
      : LocalMapping(std::move(map), LocalMappingOptions::from_config(config)) {}
  ~LocalMapping();  // stops the worker (interrupting a BA) and joins it
  LocalMapping(const LocalMapping&) = delete;
  LocalMapping& operator=(const LocalMapping&) = delete;

  void insert_keyframe(std::shared_ptr<KeyFrame> keyframe);
  // True while the worker is idle (not processing a keyframe) and not stopped.
  bool accepts_keyframes() const;
  size_t queue_size() const;
  // Asks a running local BA to finish now (tracking needs the mapper's attention).
  void interrupt_bundle_adjustment();

  // Blocks until the queue is empty and the worker idle (or stopped).
  void wait_until_idle();

  // Pause after the current keyframe; keyframes inserted meanwhile wait in the queue.
  void request_stop();
  bool is_stopped() const;
  void release();

  LocalMappingStats stats() const;

  // Called on the worker thread with each keyframe once it is processed (and not culled): the
  // input of loop closing. May be set at any time; empty = nobody listens.
  void set_keyframe_listener(std::function<void(const std::shared_ptr<KeyFrame>&)> listener);

 private:
  void run(const std::stop_token& stop);

  LocalMapper mapper_;
  mutable std::mutex mutex_;
  std::condition_variable_any wake_;  // worker: new keyframe, release, shutdown
  std::condition_variable idle_;      // wait_until_idle / stop requesters
  std::deque<std::shared_ptr<KeyFrame>> queue_;
  bool busy_ = false;
  bool stop_requested_ = false;
  bool stopped_ = false;
  std::atomic<bool> abort_bundle_adjustment_{false};
  LocalMappingStats stats_;  // copy of mapper_.stats() after each keyframe, under mutex_
  std::function<void(const std::shared_ptr<KeyFrame>&)> listener_;  // under mutex_
  // Last member: the thread starts once everything above exists, and is joined (jthread) first.
  std::jthread thread_;
};

}  // namespace pspslam
