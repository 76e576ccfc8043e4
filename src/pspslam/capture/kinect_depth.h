#pragma once

#include <array>
#include <cstdint>

#include <opencv2/core.hpp>

namespace pspslam {

// Kinect v1 raw 11-bit disparity <-> metres. libfreenect's FREENECT_DEPTH_REGISTERED mode does
// this conversion (and the registration to the colour image) with the device's own calibration;
// fakenect replays only FREENECT_DEPTH_11BIT, so raw frames are converted here with the
// published fit of 1/depth linear in the raw value (N. Burrus, Kinect calibration):
//   depth_m = 1 / (kRawScale * raw + kRawOffset)
// which is an approximation of a particular device (a few mm at 1 m, a few cm at 4 m).
inline constexpr double kKinectRawScale = -0.0030711016;
inline constexpr double kKinectRawOffset = 3.3309495161;
inline constexpr uint16_t kKinectRawNoReading = 2047;  // FREENECT_DEPTH_RAW_NO_VALUE
// Readings beyond this are noise (the sensor's range is ~0.5 .. 8 m); they become 0.
inline constexpr double kKinectMaxDepth = 10.0;

// metres for a raw value; 0 for "no reading" and for values outside the fit's range.
float kinect_raw_to_metres(uint16_t raw);
// The raw value whose depth is nearest `metres` (used to make replay dumps); 2047 for 0 or a
// depth outside 0.3 .. kKinectMaxDepth m.
uint16_t kinect_metres_to_raw(double metres);

// kinect_raw_to_metres for every raw value, so a frame costs one table look-up per pixel.
class KinectRawDepthTable {
 public:
  KinectRawDepthTable();
  // raw: CV_16UC1 raw values (only the low 11 bits are used); returns CV_32FC1 metres.
  cv::Mat convert(const cv::Mat& raw) const;

 private:
  std::array<float, 2048> metres_{};
};

}  // namespace pspslam
