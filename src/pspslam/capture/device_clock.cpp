#include "pspslam/capture/device_clock.h"

namespace pspslam {

Timestamp DeviceClock::seconds(uint32_t ticks) {
  if (last_) {
    // Modular difference read as signed: a stamp slightly older than the last one (the other
    // stream) steps back, a wrap of the counter steps forward.
    unwrapped_ += static_cast<int32_t>(ticks - *last_);
  }
  last_ = ticks;
  return origin_ + static_cast<double>(unwrapped_) / kTicksPerSecond;
}

}  // namespace pspslam
