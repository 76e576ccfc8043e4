#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pspslam {

// One step of the semantic thread's ladder: which network it runs and on which frames.
struct PaceLevel {
  int network = 0;  // index into the thread's segmenters, largest input first
  int stride = 1;   // segment every stride-th frame; the others use the newest mask, moved
};

struct SemanticPaceParams {
  double frame_period_ms = 1000.0 / 30.0;
  // Step down once the smoothed inference time exceeds this many strides of frames (the mask
  // would arrive that many strides late), for results_to_step_down results in a row.
  double step_down_periods = 2.0;
  // Step up once the time predicted for the level above is under this many of its strides, for
  // results_to_step_up results in a row. Below step_down_periods, so that the two rules never
  // hand a level back and forth (hysteresis).
  double step_up_periods = 1.5;
  int results_to_step_down = 3;
  int results_to_step_up = 10;
  double smoothing = 0.3;  // weight of the newest result in the moving average
};

// Chooses the semantic thread's level from the inference times it measures, so that masks keep
// pace with the camera: a smaller network input, then sparser frames, when inference exceeds the
// frame budget, and back up when there is room. Pure bookkeeping: the caller measures.
class SemanticPace {
 public:
  // `levels`: cheapest last. `network_cost[i]`: relative cost of network i (e.g. its input
  // pixels), used to predict the time at the level above from the time at this one.
  SemanticPace(SemanticPaceParams params, std::vector<PaceLevel> levels,
               std::vector<double> network_cost);

  // One inference of `milliseconds` at the current level; returns the level to use next.
  int observe(double milliseconds);

  int level() const { return level_; }
  const PaceLevel& current() const { return levels_[static_cast<size_t>(level_)]; }
  const std::vector<PaceLevel>& levels() const { return levels_; }
  int changes() const { return changes_; }

 private:
  double budget_ms(const PaceLevel& level, double periods) const;
  double predicted_ms(const PaceLevel& from, const PaceLevel& to) const;
  void move_to(int level);

  SemanticPaceParams params_;
  std::vector<PaceLevel> levels_;
  std::vector<double> network_cost_;
  int level_ = 0;
  double smoothed_ms_ = -1.0;  // < 0: nothing measured at this level yet
  int over_ = 0;               // consecutive results over the step-down budget
  int under_ = 0;              // consecutive results with room for the level above
  int changes_ = 0;
};

// The ladder for `networks` segmenters (largest input first): each network on every frame, then
// the smallest on every 2nd, ... up to `max_stride`.
std::vector<PaceLevel> pace_ladder(int networks, int max_stride);

}  // namespace pspslam
