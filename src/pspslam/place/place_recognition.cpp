#include "pspslam/place/place_recognition.h"

#include <algorithm>

#include "pspslam/core/error.h"
#include "pspslam/core/shared_paths.h"

namespace pspslam {

std::filesystem::path default_vocabulary_path() {
  return data_dir() / "models" / "vocabulary" / "orb_k10_l5.pspvoc";
}

PlaceRecognition::PlaceRecognition(std::shared_ptr<const Vocabulary> vocabulary)
    : vocabulary_(std::move(vocabulary)),
      direct_index_level_(vocabulary_ ? std::min(kDirectIndexLevel, vocabulary_->levels()) : 0),
      database_(vocabulary_ ? vocabulary_->word_count() : 0) {
  if (!vocabulary_) throw Error("place recognition: no vocabulary given");
}

std::shared_ptr<PlaceRecognition> PlaceRecognition::load(
    const std::filesystem::path& vocabulary_file) {
  return std::make_shared<PlaceRecognition>(
      std::make_shared<const Vocabulary>(Vocabulary::load(vocabulary_file)));
}

}  // namespace pspslam
