#pragma once

#include <vector>

#include "pspslam/people/people_score.h"
#include "pspslam/synth/scene.h"

namespace pspslam {

// Every walking person of a rendered frame as people.txt holds her: id (the body's index), the
// centre of her torso and its velocity (world, at the colour image's instant) and the pixels of
// the colour image that show her (the person-labelled surfaces of her body; not a carried box).
std::vector<PersonTruth> people_truth(const SyntheticScene& scene, const SynthFrame& frame);

}  // namespace pspslam
