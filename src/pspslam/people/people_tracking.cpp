#include "pspslam/people/people_tracking.h"

#include "pspslam/core/thread_cpu_time.h"

namespace pspslam {

PeopleFrame PeopleTracking::process(Timestamp timestamp, const cv::Mat& labels,
                                    const cv::Mat& depth,
                                    const std::optional<Pose>& T_world_camera) {
  const double cpu_start = thread_cpu_ms();
  PeopleFrame frame;
  std::vector<PersonObservation> observations;
  frame.observed = !labels.empty() && !depth.empty() && T_world_camera.has_value();
  if (frame.observed)
    observations = detector_.detect(labels, person_label_, depth, camera_, *T_world_camera);
  frame.instances = static_cast<int>(observations.size());
  frame.people = tracker_.update(timestamp, observations);
  frame.cpu_ms = thread_cpu_ms() - cpu_start;
  return frame;
}

}  // namespace pspslam
