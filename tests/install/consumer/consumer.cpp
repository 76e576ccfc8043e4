// Feeds an RGB-D sequence through the public API: frames in, pose and dynamic mask out.
//   consumer SEQUENCE_DIR   prints "frames N tracked T masked_frames M model PATH"
#include <opencv2/core.hpp>

#include <iostream>

#include "pspslam/io/sequence_setup.h"
#include "pspslam/system/system.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: consumer SEQUENCE_DIR\n";
    return 2;
  }
  try {
    const pspslam::SequenceSetup setup =
        pspslam::open_sequence_with_config(argv[1], std::nullopt, nullptr);
    pspslam::SystemOptions options;
    options.dynamic.mode = pspslam::DynamicMode::full;
    options.dynamic.model = std::filesystem::path(PSPSLAM_DATA) / "models/pspnet/pspnet.yaml";
    options.place.relocalization = false;
    options.place.loop_closing = false;
    options.back_end_wait = pspslam::BackEndWait::whole_back_end;
    pspslam::System system(setup.config, options);
    size_t tracked = 0, masked = 0;
    for (size_t i = 0; i < setup.sequence->size(); ++i) {
      const pspslam::FrameReport report = system.process(setup.sequence->load(i));
      if (report.tracking.T_world_camera) ++tracked;
      const cv::Mat mask = system.last_dynamic_mask();
      if (!mask.empty() && cv::countNonZero(mask) > 0) ++masked;
    }
    system.shutdown();
    std::cout << "frames " << setup.sequence->size() << " tracked " << tracked << " masked_frames "
              << masked << " model " << options.dynamic.model.string() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "consumer: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
