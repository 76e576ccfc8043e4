#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include "pspslam/people/people_score.h"

namespace pspslam {
namespace {

PersonTruth truth(double t, int id, double x, int pixels) {
  return {t, id, Eigen::Vector3d(x, 0, 1), Eigen::Vector3d(1, 0, 0), pixels};
}

PersonEstimate estimate(double t, int id, double x) {
  PersonEstimate row{t, {}};
  row.person.id = id;
  row.person.position = Eigen::Vector3d(x, 0, 1);
  row.person.velocity = Eigen::Vector3d(1, 0.1, 0);
  row.person.visible_pixels = 3000;
  return row;
}

TEST(PeopleScore, CountsTrackedMissedFalseAndIdSwitches) {
  std::vector<PersonTruth> people;
  std::vector<PersonEstimate> tracks;
  for (int f = 0; f < 60; ++f) {
    const double t = f / 30.0;
    people.push_back(truth(t, 0, 0.0 + t, 5000));
    people.push_back(truth(t, 1, 3.0, f < 30 ? 5000 : 1000));  // small later: not required
    if (f != 10) tracks.push_back(estimate(t, 7, 0.05 + t));   // missed once
    if (f < 20) tracks.push_back(estimate(t, 8, 3.0));
    if (f >= 25) tracks.push_back(estimate(t, 9, 3.0));    // a new id for person 1: one switch
    if (f == 40) tracks.push_back(estimate(t, 10, -5.0));  // nobody there
  }
  const PeopleScore score =
      score_people(people, tracks, [](Timestamp) { return std::optional<Pose>(Pose::Identity()); });
  EXPECT_EQ(score.person_frames, 60 + 30);
  EXPECT_EQ(score.tracked, 59 + 25);
  EXPECT_EQ(score.reported, 59 + 20 + 35 + 1);
  EXPECT_EQ(score.false_reports, 1);
  EXPECT_EQ(score.id_switches, 1);
  EXPECT_EQ(score.distinct_ids, 4);
  EXPECT_NEAR(score.person_minutes, 90.0 / 30.0 / 60.0, 1e-6);
  // 59 matches 5 cm off (person 0), 55 exact (person 1).
  EXPECT_NEAR(score.median_position_error_m, 0.05, 1e-9);
  EXPECT_NEAR(score.p90_position_error_m, 0.05, 1e-9);
  EXPECT_NEAR(score.median_velocity_error_mps, 0.1, 1e-9);
}

TEST(PeopleScore, TheRunsWorldIsMovedIntoTheTruthsAndUnposedFramesAreSkipped) {
  const std::vector<PersonTruth> people = {truth(0.0, 0, 2.0, 5000), truth(1.0, 0, 2.0, 5000)};
  const std::vector<PersonEstimate> tracks = {estimate(0.0, 1, 1.0)};
  Pose shift = Pose::Identity();
  shift.translation() = Eigen::Vector3d(1.0, 0.0, 0.0);
  const PeopleScore score = score_people(people, tracks, [&](Timestamp t) {
    return t < 0.5 ? std::optional<Pose>(shift) : std::nullopt;
  });
  EXPECT_EQ(score.person_frames, 1);
  EXPECT_EQ(score.tracked, 1);
  EXPECT_NEAR(score.median_position_error_m, 0.0, 1e-9);
}

TEST(PeopleScore, TruthFileRoundTripsAndAMalformedLineIsNamed) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "pspslam_people_truth";
  std::filesystem::create_directories(dir);
  const std::vector<PersonTruth> rows = {truth(1000000.033333, 2, 1.25, 4321)};
  write_people_truth(dir / "people.txt", rows);
  const std::vector<PersonTruth> read = read_people_truth(dir / "people.txt");
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].id, 2);
  EXPECT_EQ(read[0].visible_pixels, 4321);
  EXPECT_NEAR(read[0].timestamp, 1000000.033333, 1e-7);
  EXPECT_NEAR(read[0].position.x(), 1.25, 1e-9);
  {
    std::ofstream bad(dir / "bad.txt");
    bad << "# header\n1.0 2 3\n";
  }
  try {
    read_people_truth(dir / "bad.txt");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:2: expected"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pspslam
