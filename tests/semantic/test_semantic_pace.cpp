#include <gtest/gtest.h>

#include <set>

#include "pspslam/core/error.h"
#include "pspslam/semantic/semantic_delay.h"
#include "pspslam/semantic/semantic_pace.h"

namespace pspslam {
namespace {

TEST(SemanticDelay, ParsesAFixedAndARandomDelay) {
  EXPECT_EQ(parse_semantic_delay("0", "--d"), (SemanticDelay{0, 0}));
  EXPECT_EQ(parse_semantic_delay("300", "--d"), (SemanticDelay{300, 300}));
  EXPECT_EQ(parse_semantic_delay("random:50:250", "--d"), (SemanticDelay{50, 250}));
  EXPECT_FALSE(parse_semantic_delay("0", "--d").active());
  EXPECT_TRUE(parse_semantic_delay("random:0:5", "--d").active());
}

TEST(SemanticDelay, RefusesMalformedValuesNamingTheFlag) {
  for (const char* bad : {"", "-5", "12ms", "random:", "random:5", "random:9:3", "random:1:2:3",
                          "20000", "1.5", "random:-1:4"}) {
    try {
      parse_semantic_delay(bad, "--semantic-delay-ms");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--semantic-delay-ms"), std::string::npos);
    }
  }
}

TEST(SemanticDelay, RandomDrawsStayInRangeAndRepeatWithTheSeed) {
  const SemanticDelay delay{10, 20, 7};
  SemanticDelayDraw first(delay);
  SemanticDelayDraw second(delay);
  std::set<long> seen;
  for (int i = 0; i < 200; ++i) {
    const long a = first.next().count();
    EXPECT_EQ(a, second.next().count());
    EXPECT_GE(a, 10);
    EXPECT_LE(a, 20);
    seen.insert(a);
  }
  EXPECT_GT(seen.size(), 5u);  // really random, not one value
  SemanticDelayDraw fixed(SemanticDelay{40, 40});
  EXPECT_EQ(fixed.next().count(), 40);
}

SemanticPaceParams pace_params() {
  SemanticPaceParams params;
  params.frame_period_ms = 30.0;  // step down above 60 ms per stride, up below 45 ms
  params.results_to_step_down = 3;
  params.results_to_step_up = 4;
  params.smoothing = 1.0;  // no averaging: each result decides alone
  return params;
}

// Two networks (the second half the cost), then the smaller one on every 2nd and 3rd frame.
SemanticPace three_step_pace() { return {pace_params(), pace_ladder(2, 3), {2.0, 1.0}}; }

TEST(SemanticPace, TheLadderShrinksTheInputFirstThenSegmentsSparser) {
  const std::vector<PaceLevel> ladder = pace_ladder(2, 3);
  ASSERT_EQ(ladder.size(), 4u);
  EXPECT_EQ(ladder[0].network, 0);
  EXPECT_EQ(ladder[0].stride, 1);
  EXPECT_EQ(ladder[1].network, 1);
  EXPECT_EQ(ladder[1].stride, 1);
  EXPECT_EQ(ladder[2].network, 1);
  EXPECT_EQ(ladder[2].stride, 2);
  EXPECT_EQ(ladder[3].stride, 3);
}

TEST(SemanticPace, StaysWhileInferenceFitsTheBudget) {
  SemanticPace pace = three_step_pace();
  for (int i = 0; i < 50; ++i) EXPECT_EQ(pace.observe(55.0), 0);
  EXPECT_EQ(pace.changes(), 0);
}

TEST(SemanticPace, StepsDownOnlyAfterSeveralSlowResultsInARow) {
  SemanticPace pace = three_step_pace();
  EXPECT_EQ(pace.observe(80.0), 0);
  EXPECT_EQ(pace.observe(80.0), 0);
  EXPECT_EQ(pace.observe(40.0), 0);  // one fast result resets the count
  EXPECT_EQ(pace.observe(80.0), 0);
  EXPECT_EQ(pace.observe(80.0), 0);
  EXPECT_EQ(pace.observe(80.0), 1);  // the smaller network
  EXPECT_EQ(pace.current().network, 1);
}

TEST(SemanticPace, ReachesTheSparsestLevelUnderAPersistentDelayAndStopsThere) {
  SemanticPace pace = three_step_pace();
  for (int i = 0; i < 40; ++i) pace.observe(300.0);
  EXPECT_EQ(pace.level(), 3);
  EXPECT_EQ(pace.current().stride, 3);
  EXPECT_EQ(pace.changes(), 3);
}

TEST(SemanticPace, StepsBackUpWhenThereIsRoomWithoutOscillating) {
  SemanticPace pace = three_step_pace();
  for (int i = 0; i < 3; ++i) pace.observe(100.0);
  ASSERT_EQ(pace.level(), 1);
  // 30 ms on the smaller network predicts 60 ms on the larger one: over the 45 ms of room.
  for (int i = 0; i < 20; ++i) EXPECT_EQ(pace.observe(30.0), 1);
  // 20 ms predicts 40 ms: room, after four results in a row.
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pace.observe(20.0), 1);
  EXPECT_EQ(pace.observe(20.0), 0);
  // Back on the larger network at 40 ms, well inside its 60 ms budget: it stays.
  for (int i = 0; i < 20; ++i) EXPECT_EQ(pace.observe(40.0), 0);
  EXPECT_EQ(pace.changes(), 2);
}

TEST(SemanticPace, RefusesLevelsWithoutACostedNetwork) {
  EXPECT_THROW(SemanticPace(pace_params(), {}, {1.0}), Error);
  EXPECT_THROW(SemanticPace(pace_params(), {{1, 1}}, {1.0}), Error);
  EXPECT_THROW(SemanticPace(pace_params(), {{0, 0}}, {1.0}), Error);
}

}  // namespace
}  // namespace pspslam
