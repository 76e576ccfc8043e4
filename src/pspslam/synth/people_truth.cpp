#include "pspslam/synth/people_truth.h"

namespace pspslam {

std::vector<PersonTruth> people_truth(const SyntheticScene& scene, const SynthFrame& frame) {
  const int bodies = scene.body_count();
  std::vector<int> pixels(static_cast<size_t>(bodies), 0);
  for (int y = 0; y < frame.surface_ids.rows; ++y) {
    const auto* row = frame.surface_ids.ptr<std::uint16_t>(y);
    for (int x = 0; x < frame.surface_ids.cols; ++x) {
      const int body = scene.person_of_surface(row[x]);
      if (body >= 0) ++pixels[static_cast<size_t>(body)];
    }
  }
  const double t = frame.timestamp - scene.timestamp(0);
  constexpr double kStep_s = 0.01;  // central difference of the exact motion
  std::vector<PersonTruth> people;
  for (int body = 0; body < bodies; ++body) {
    PersonTruth person;
    person.timestamp = frame.timestamp;
    person.id = body;
    person.position = scene.body_centre_at(body, t);
    person.velocity =
        (scene.body_centre_at(body, t + kStep_s) - scene.body_centre_at(body, t - kStep_s)) /
        (2.0 * kStep_s);
    person.visible_pixels = pixels[static_cast<size_t>(body)];
    people.push_back(person);
  }
  return people;
}

}  // namespace pspslam
