#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <thread>

#include "pspslam/core/error.h"
#include "pspslam/place/keyframe_database.h"

namespace pspslam {
namespace {

// Uniform weights over the given words (sorted), L1-normalised.
BowVector bow_of(std::vector<WordId> words) {
  std::sort(words.begin(), words.end());
  BowVector bow;
  for (const WordId w : words) bow.entries.push_back({w, 1.0f / static_cast<float>(words.size())});
  return bow;
}

std::vector<KeyFrameId> ids_of(const std::vector<PlaceCandidate>& candidates) {
  std::vector<KeyFrameId> ids;
  for (const PlaceCandidate& c : candidates) ids.push_back(c.id);
  return ids;
}

TEST(KeyFrameDatabase, AddEraseAndSize) {
  KeyFrameDatabase db(100);
  db.add(1, bow_of({1, 2, 3}));
  db.add(2, bow_of({3, 4}));
  EXPECT_EQ(db.size(), 2u);
  EXPECT_TRUE(db.contains(1));
  EXPECT_TRUE(db.erase(1));
  EXPECT_FALSE(db.erase(1));
  EXPECT_FALSE(db.contains(1));
  EXPECT_EQ(db.size(), 1u);
  // Re-adding an id replaces its words.
  db.add(2, bow_of({7, 8}));
  EXPECT_TRUE(db.query(bow_of({3, 4}), nullptr).empty());
  EXPECT_EQ(ids_of(db.query(bow_of({7, 8}), nullptr)), (std::vector<KeyFrameId>{2}));
  db.clear();
  EXPECT_EQ(db.size(), 0u);
  EXPECT_TRUE(db.query(bow_of({7, 8}), nullptr).empty());
}

TEST(KeyFrameDatabase, RejectsWordsOutsideTheVocabulary) {
  KeyFrameDatabase db(10);
  try {
    db.add(5, bow_of({3, 12}));
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "keyframe database: keyframe 5 has word 12 but the vocabulary has 10 words "
                 "(BoW vector from another vocabulary?)");
  }
  EXPECT_EQ(db.size(), 0u);
}

TEST(KeyFrameDatabase, CommonWordThresholdScoresAndExclusion) {
  KeyFrameDatabase db(100);
  db.add(10, bow_of({1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));    // shares 10 with the query
  db.add(11, bow_of({1, 2, 3, 4, 5, 6, 7, 8, 50, 51}));   // shares 8 = 0.8 * 10: kept
  db.add(12, bow_of({1, 2, 3, 4, 5, 6, 7, 60, 61, 62}));  // shares 7 < 8: dropped
  db.add(13, bow_of({70, 71}));                           // shares nothing
  const BowVector query = bow_of({1, 2, 3, 4, 5, 6, 7, 8, 9, 10});

  // Without covisibility every keyframe is its own group; groups >= 0.75 * best are returned.
  const std::vector<PlaceCandidate> result = db.query(query, nullptr);
  ASSERT_EQ(result.size(), 2u);
  EXPECT_EQ(result[0].id, 10u);
  EXPECT_DOUBLE_EQ(result[0].score, 1.0);
  EXPECT_EQ(result[0].common_words, 10u);
  EXPECT_EQ(result[1].id, 11u);
  EXPECT_NEAR(result[1].score, 0.8, 1e-6);

  // Scores below min_score are dropped; excluded keyframes do not even set the common-word
  // maximum (loop closing excludes the query's covisible neighbours).
  PlaceQueryOptions options;
  options.excluded = {10};
  const std::vector<PlaceCandidate> loop = db.query(query, nullptr, options);
  // Max common is now 8 (keyframe 11): threshold 6.4, so 12 (7 common) is back in.
  EXPECT_EQ(ids_of(loop), (std::vector<KeyFrameId>{11, 12}));
  options.min_score = 0.75;
  EXPECT_EQ(ids_of(db.query(query, nullptr, options)), (std::vector<KeyFrameId>{11}));

  const std::vector<PlaceCandidate> all = db.score_all(query);
  ASSERT_EQ(all.size(), 4u);
  EXPECT_EQ(ids_of(all), (std::vector<KeyFrameId>{10, 11, 12, 13}));
  EXPECT_DOUBLE_EQ(all[3].score, 0.0);
}

TEST(KeyFrameDatabase, CovisibilityGroupsAccumulateScores) {
  KeyFrameDatabase db(100);
  // A group of three moderately similar keyframes (20, 21, 22) and one lone keyframe (30) that
  // scores best on its own: the group wins, represented by its best member.
  db.add(20, bow_of({1, 2, 3, 4, 5, 40, 41, 42, 43, 44}));  // 0.5
  db.add(21, bow_of({1, 2, 3, 4, 5, 6, 45, 46, 47, 48}));   // 0.6
  db.add(22, bow_of({1, 2, 3, 4, 5, 49, 50, 51, 52, 53}));  // 0.5
  db.add(30, bow_of({1, 2, 3, 4, 5, 6, 7, 60, 61, 62}));    // 0.7
  const BowVector query = bow_of({1, 2, 3, 4, 5, 6, 7, 8, 9, 10});
  const CovisibilityFn covisible = [](KeyFrameId id) -> std::vector<KeyFrameId> {
    if (id == 20) return {21, 22};
    if (id == 21) return {20, 22};
    if (id == 22) return {21, 20};
    return {};
  };
  PlaceQueryOptions options;
  options.min_common_ratio = 0.0;
  const std::vector<PlaceCandidate> result = db.query(query, covisible, options);
  ASSERT_FALSE(result.empty());
  EXPECT_EQ(result[0].id, 21u);
  EXPECT_NEAR(result[0].score, 0.6, 1e-6);
  EXPECT_NEAR(result[0].group_score, 1.6, 1e-6);
  // 30's group scores 0.7 < 0.75 * 1.6: not returned; 21 is returned once though three groups
  // elect it.
  EXPECT_EQ(ids_of(result), (std::vector<KeyFrameId>{21}));
  // Only group_size neighbours count.
  options.group_size = 1;
  const std::vector<PlaceCandidate> small = db.query(query, covisible, options);
  ASSERT_FALSE(small.empty());
  EXPECT_NEAR(small[0].group_score, 1.1, 1e-6);
}

TEST(KeyFrameDatabase, ErasedKeyframesAreNeverReturned) {
  KeyFrameDatabase db(1000);
  for (KeyFrameId id = 0; id < 50; ++id) {
    db.add(id, bow_of({static_cast<WordId>(id), static_cast<WordId>(id + 1), 999}));
  }
  for (KeyFrameId id = 0; id < 50; id += 2) EXPECT_TRUE(db.erase(id));
  // The covisibility callback still names erased keyframes (the map may lag behind).
  const CovisibilityFn covisible = [](KeyFrameId id) {
    return std::vector<KeyFrameId>{id > 0 ? id - 1 : id + 1, id + 1};
  };
  PlaceQueryOptions options;
  options.retain_ratio = 0.0;
  options.min_common_ratio = 0.0;
  for (WordId w = 0; w < 51; ++w) {
    for (const PlaceCandidate& c : db.query(bow_of({w, 999}), covisible, options)) {
      EXPECT_EQ(c.id % 2, 1u) << "erased keyframe " << c.id << " returned for word " << w;
    }
  }
  for (const PlaceCandidate& c : db.score_all(bow_of({4, 5}))) EXPECT_EQ(c.id % 2, 1u);
}

TEST(KeyFrameDatabase, ConcurrentAddEraseAndQuery) {
  KeyFrameDatabase db(64);
  // Keyframes that stay, one per word, so every query has an answer however threads interleave.
  for (WordId w = 0; w < 64; ++w) db.add(100000 + w, bow_of({w}));
  std::atomic<bool> writing{true};
  std::thread writer([&] {
    for (KeyFrameId id = 0; id < 2000; ++id) {
      db.add(id, bow_of({static_cast<WordId>(id % 64), static_cast<WordId>((id + 1) % 64)}));
      if (id >= 10) db.erase(id - 10);
    }
    writing = false;
  });
  std::size_t queries = 0;
  std::size_t unanswered = 0;
  while (writing || queries < 1000) {
    const WordId w = static_cast<WordId>(queries % 64);
    const std::vector<PlaceCandidate> result = db.query(bow_of({w}), nullptr);
    if (result.empty()) ++unanswered;
    for (const PlaceCandidate& c : result) {
      // Only keyframes holding the word: a fixed one, or one the writer added and not yet erased.
      EXPECT_TRUE(c.id == 100000 + w || c.id % 64 == w || (c.id + 1) % 64 == w) << c.id;
    }
    ++queries;
  }
  writer.join();
  EXPECT_EQ(unanswered, 0u);
  EXPECT_EQ(db.size(), 64u + 10u);
}

}  // namespace
}  // namespace pspslam
