#pragma once

#include <cstdint>
#include <optional>

#include "pspslam/core/types.h"

namespace pspslam {

// Turns a Kinect v1's frame time stamps into seconds. The device stamps every colour and depth
// frame with a 32-bit counter of a 60 MHz clock, which wraps every 71.6 s; the clock unwraps it
// (consecutive stamps of either stream are far less than half a wrap apart) and places the first
// stamp at `origin` (the computer's wall clock when the first frame arrived, so recordings carry
// Unix times like the TUM sequences).
class DeviceClock {
 public:
  static constexpr double kTicksPerSecond = 60e6;

  explicit DeviceClock(Timestamp origin) : origin_(origin) {}
  Timestamp seconds(uint32_t ticks);

 private:
  Timestamp origin_;
  std::optional<uint32_t> last_;
  int64_t unwrapped_ = 0;  // ticks since the first stamp
};

}  // namespace pspslam
