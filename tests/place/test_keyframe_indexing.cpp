#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <set>

#include "pspslam/core/error.h"
#include "pspslam/map/keyframe.h"
#include "pspslam/map/map.h"
#include "pspslam/place/place_recognition.h"
#include "pspslam/synth/scene.h"
#include "pspslam/synth/sequence_writer.h"
#include "pspslam/system/system.h"
#include "support/input_frames.h"

namespace pspslam {
namespace {

// Every keyframe local mapping keeps is indexed with its BoW vector; culled ones leave the
// database. Runs the real threads on a short synthetic sequence.
TEST(KeyFrameIndexing, DatabaseHoldsExactlyTheMapsKeyframesAfterLocalMapping) {
  SynthOptions synth;
  synth.frames = 90;
  synth.bodies = 0;
  synth.seed = 3;
  synth.threads = 1;
  const SyntheticScene scene(synth);
  System system(synthetic_system_config());
  ASSERT_NE(system.place_recognition(), nullptr) << "relocalisation is on by default";
  SynthFrame frame;
  cv::Mat gray;
  for (size_t i = 0; i < scene.frame_count(); ++i) {
    scene.render(i, frame, 1);
    cv::cvtColor(frame.bgr, gray, cv::COLOR_BGR2GRAY);
    system.process(grey_depth_frame(scene.timestamp(i), gray, frame.depth_sensor));
  }
  system.shutdown();

  const KeyFrameDatabase& database = system.place_recognition()->database();
  const auto keyframes = system.map().keyframes();
  ASSERT_GE(keyframes.size(), 3u);
  EXPECT_EQ(database.size(), keyframes.size());
  for (const auto& keyframe : keyframes) {
    EXPECT_TRUE(database.contains(keyframe->id())) << "keyframe " << keyframe->id();
    ASSERT_TRUE(keyframe->has_bow()) << "keyframe " << keyframe->id();
    EXPECT_GT(keyframe->bow_vector().size(), 50u) << "keyframe " << keyframe->id();
    // Every keypoint is in exactly one node of the direct index.
    size_t indexed = 0;
    const FeatureVector& features = keyframe->feature_vector();
    for (size_t n = 0; n < features.node_count(); ++n) indexed += features.features(n).size();
    EXPECT_EQ(indexed, static_cast<size_t>(keyframe->size()));
  }
  // A keyframe is its own best match in the database.
  const auto& probe = keyframes[keyframes.size() / 2];
  const auto ranked = database.score_all(probe->bow_vector());
  ASSERT_FALSE(ranked.empty());
  EXPECT_EQ(ranked.front().id, probe->id());
  EXPECT_NEAR(ranked.front().score, 1.0, 1e-6);
}

TEST(KeyFrameIndexing, MissingVocabularyIsAClearErrorNamingTheFile) {
  SystemOptions options;
  options.place.vocabulary = "/nonexistent/vocabulary.pspvoc";
  try {
    System system(synthetic_system_config(), options);
    FAIL() << "expected pspslam::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/vocabulary.pspvoc"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace pspslam
