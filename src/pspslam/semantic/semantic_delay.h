#pragma once

#include <chrono>
#include <cstdint>
#include <random>
#include <string>

namespace pspslam {

// Fault injection for tests and experiments (`pspslam run --semantic-delay-ms`): an extra wait
// after each segmentation, as if the network had run that much longer. It reproduces a network
// that falls behind the camera (a loaded or slower CPU) on demand, without loading the machine.
struct SemanticDelay {
  int min_ms = 0;
  int max_ms = 0;          // == min_ms: a fixed delay
  std::uint32_t seed = 1;  // of the random draws (min_ms < max_ms)
  bool active() const { return max_ms > 0; }
  bool operator==(const SemanticDelay&) const = default;
};

// "MS" (a fixed delay) or "random:MIN:MAX" (uniform, whole milliseconds, MIN <= MAX), each at
// most 10 s. Throws pspslam::Error naming `flag` and the accepted forms.
SemanticDelay parse_semantic_delay(const std::string& value, const std::string& flag);

// Draws the delays of one SemanticDelay: the same seed gives the same sequence.
class SemanticDelayDraw {
 public:
  explicit SemanticDelayDraw(const SemanticDelay& delay);
  std::chrono::milliseconds next();

 private:
  SemanticDelay delay_;
  std::mt19937 generator_;
};

}  // namespace pspslam
