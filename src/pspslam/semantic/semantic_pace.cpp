#include "pspslam/semantic/semantic_pace.h"

#include "pspslam/core/error.h"

namespace pspslam {

SemanticPace::SemanticPace(SemanticPaceParams params, std::vector<PaceLevel> levels,
                           std::vector<double> network_cost)
    : params_(params), levels_(std::move(levels)), network_cost_(std::move(network_cost)) {
  if (levels_.empty()) throw Error("SemanticPace: no levels");
  for (const PaceLevel& level : levels_) {
    if (level.network < 0 || static_cast<size_t>(level.network) >= network_cost_.size() ||
        level.stride < 1 || network_cost_[static_cast<size_t>(level.network)] <= 0.0)
      throw Error("SemanticPace: a level names no costed network or has a stride below 1");
  }
}

double SemanticPace::budget_ms(const PaceLevel& level, double periods) const {
  return periods * params_.frame_period_ms * level.stride;
}

double SemanticPace::predicted_ms(const PaceLevel& from, const PaceLevel& to) const {
  return smoothed_ms_ * network_cost_[static_cast<size_t>(to.network)] /
         network_cost_[static_cast<size_t>(from.network)];
}

int SemanticPace::observe(double milliseconds) {
  smoothed_ms_ = smoothed_ms_ < 0.0
                     ? milliseconds
                     : params_.smoothing * milliseconds + (1.0 - params_.smoothing) * smoothed_ms_;
  const PaceLevel& here = current();
  const bool can_go_down = static_cast<size_t>(level_) + 1 < levels_.size();
  over_ = smoothed_ms_ > budget_ms(here, params_.step_down_periods) ? over_ + 1 : 0;
  if (level_ > 0) {
    const PaceLevel& above = levels_[static_cast<size_t>(level_) - 1];
    under_ = predicted_ms(here, above) < budget_ms(above, params_.step_up_periods) ? under_ + 1 : 0;
  }
  if (can_go_down && over_ >= params_.results_to_step_down) {
    move_to(level_ + 1);
  } else if (level_ > 0 && under_ >= params_.results_to_step_up) {
    const PaceLevel from = here;
    const PaceLevel& to = levels_[static_cast<size_t>(level_) - 1];
    const double expected = predicted_ms(from, to);
    move_to(level_ - 1);
    smoothed_ms_ = expected;  // start the new level from the prediction, not from zero
  }
  return level_;
}

void SemanticPace::move_to(int level) {
  if (level > level_) {
    // The time measured at the level above predicts the one below (cheaper network).
    smoothed_ms_ = predicted_ms(current(), levels_[static_cast<size_t>(level)]);
  }
  level_ = level;
  over_ = 0;
  under_ = 0;
  ++changes_;
}

std::vector<PaceLevel> pace_ladder(int networks, int max_stride) {
  std::vector<PaceLevel> levels;
  for (int network = 0; network < networks; ++network) levels.push_back({network, 1});
  for (int stride = 2; stride <= max_stride; ++stride) levels.push_back({networks - 1, stride});
  return levels;
}

}  // namespace pspslam
