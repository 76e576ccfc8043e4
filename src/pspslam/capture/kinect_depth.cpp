#include "pspslam/capture/kinect_depth.h"

#include <cmath>

namespace pspslam {

float kinect_raw_to_metres(uint16_t raw) {
  if (raw >= kKinectRawNoReading) return 0.0f;
  const double inverse = kKinectRawScale * raw + kKinectRawOffset;
  if (!(inverse > 1.0 / kKinectMaxDepth)) return 0.0f;
  return static_cast<float>(1.0 / inverse);
}

uint16_t kinect_metres_to_raw(double metres) {
  if (!(metres > 0.0) || metres > kKinectMaxDepth) return kKinectRawNoReading;
  const long raw = std::lround((1.0 / metres - kKinectRawOffset) / kKinectRawScale);
  if (raw < 0 || raw >= kKinectRawNoReading) return kKinectRawNoReading;
  return static_cast<uint16_t>(raw);
}

KinectRawDepthTable::KinectRawDepthTable() {
  for (size_t raw = 0; raw < metres_.size(); ++raw)
    metres_[raw] = kinect_raw_to_metres(static_cast<uint16_t>(raw));
}

cv::Mat KinectRawDepthTable::convert(const cv::Mat& raw) const {
  CV_Assert(raw.type() == CV_16UC1);
  cv::Mat metres(raw.size(), CV_32FC1);
  for (int y = 0; y < raw.rows; ++y) {
    const uint16_t* in = raw.ptr<uint16_t>(y);
    float* out = metres.ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x) out[x] = metres_[in[x] & 0x7ff];
  }
  return metres;
}

}  // namespace pspslam
