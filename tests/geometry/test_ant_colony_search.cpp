#include <gtest/gtest.h>

#include <random>

#include "pspslam/core/error.h"
#include "pspslam/core/yaml_section.h"
#include "pspslam/geometry/ant_colony_search.h"
#include "pspslam/geometry/convex_hull.h"

namespace pspslam {
namespace {

const cv::Size kImage(640, 480);

struct PlantedSet {
  std::vector<Eigen::Vector2f> points;
  std::vector<int> cluster;  // -1 = static background, else planted cluster id
  int clusters = 0;
};

enum class Density { sparse, dense, clustered };

// Background points plus planted dynamic people (upright ellipses).
PlantedSet make_set(Density density, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> x(0.0f, 639.0f), y(0.0f, 479.0f), unit(0.0f, 1.0f);
  PlantedSet set;
  const int background = density == Density::sparse ? 300 : 2000;
  if (density == Density::clustered) {
    // Texture clumps: background concentrated in a few blobs, like ORB on real scenes.
    std::normal_distribution<float> spread(0.0f, 25.0f);
    for (int blob = 0; blob < 40; ++blob) {
      const Eigen::Vector2f c(x(rng), y(rng));
      for (int k = 0; k < background / 40; ++k) {
        const Eigen::Vector2f p = c + Eigen::Vector2f(spread(rng), spread(rng));
        if (p.x() < 0 || p.y() < 0 || p.x() >= 640 || p.y() >= 480) continue;
        set.points.push_back(p);
        set.cluster.push_back(-1);
      }
    }
  } else {
    for (int k = 0; k < background; ++k) {
      set.points.emplace_back(x(rng), y(rng));
      set.cluster.push_back(-1);
    }
  }
  set.clusters = 3;
  const int per_cluster = density == Density::sparse ? 25 : 120;
  for (int c = 0; c < set.clusters; ++c) {
    // Upright ellipses 40-80 px wide and 120-220 px tall: people between ~1.5 and 4 m away.
    const Eigen::Vector2f semi_axes(20.0f + 20.0f * unit(rng), 60.0f + 50.0f * unit(rng));
    const Eigen::Vector2f centre(60.0f + 520.0f * unit(rng), 120.0f + 240.0f * unit(rng));
    // Background points falling inside a planted ellipse belong to it (it is one object).
    for (size_t i = 0; i < set.points.size(); ++i)
      if ((set.points[i] - centre).cwiseQuotient(semi_axes).norm() < 1.0f) set.cluster[i] = c;
    for (int k = 0; k < per_cluster; ++k) {
      const float r = std::sqrt(unit(rng)), angle = 6.2831853f * unit(rng);
      set.points.push_back(
          centre + r * semi_axes.cwiseProduct(Eigen::Vector2f(std::cos(angle), std::sin(angle))));
      set.cluster.push_back(c);
    }
  }
  return set;
}

TEST(AntColonySearch, FindsEveryPlantedClusterTestingFewerPoints) {
  for (Density density : {Density::sparse, Density::dense, Density::clustered}) {
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
      const PlantedSet set = make_set(density, seed);
      std::vector<int> calls(set.points.size(), 0);
      const PointPredicate is_dynamic = [&](int i) {
        ++calls[i];
        return set.cluster[i] >= 0;
      };
      DynamicPointSearch search;
      const SearchResult& r = search.run(set.points, kImage, is_dynamic);
      int planted = 0, found = 0;
      std::vector<int> found_per_cluster(set.clusters, 0);
      for (size_t i = 0; i < set.points.size(); ++i) {
        EXPECT_LE(calls[i], 1) << "a point was tested twice";
        if (set.cluster[i] < 0) {
          EXPECT_FALSE(r.dynamic[i]);
          continue;
        }
        ++planted;
        if (r.dynamic[i]) {
          ++found;
          ++found_per_cluster[set.cluster[i]];
        }
      }
      const std::string where =
          "density " + std::to_string(static_cast<int>(density)) + " seed " + std::to_string(seed);
      for (int c = 0; c < set.clusters; ++c) EXPECT_GT(found_per_cluster[c], 0) << where;
      // Sparse discs have gaps near the band width, so a few rim points may stay untested.
      EXPECT_GE(found, (density == Density::sparse ? 0.9 : 0.97) * planted) << where;
      // Static points tested = the path's share (~25 %) plus the 80 px bands around three
      // people (each band ~ a quarter of the image): about half of the background.
      const int background = static_cast<int>(set.points.size()) - planted;
      EXPECT_LT(r.tested_count - found, 0.65 * background) << where;
      EXPECT_EQ(r.dynamic_count, found);

      DynamicPointSearch exhaustive(AntColonyParams{.strategy = SearchStrategy::exhaustive});
      const SearchResult& all =
          exhaustive.run(set.points, kImage, [&](int i) { return set.cluster[i] >= 0; });
      EXPECT_EQ(all.tested_count, static_cast<int>(set.points.size()));
      EXPECT_EQ(all.dynamic_count, planted);
    }
  }
}

TEST(AntColonySearch, TerminatesOnAdversarialSets) {
  DynamicPointSearch search;
  const auto always = [](int) { return true; };
  // Everything dynamic, dense: one community swallows the image; each round adds >= 1 point.
  std::vector<Eigen::Vector2f> grid;
  for (int y = 0; y < 480; y += 8)
    for (int x = 0; x < 640; x += 8) grid.emplace_back(x, y);
  const SearchResult& all = search.run(grid, kImage, always);
  EXPECT_EQ(all.tested_count, static_cast<int>(grid.size()));
  EXPECT_EQ(all.dynamic_count, static_cast<int>(grid.size()));
  EXPECT_LE(all.band_rounds, static_cast<int>(grid.size()) + all.communities);

  // Collinear points: the hull degenerates to a segment.
  std::vector<Eigen::Vector2f> line;
  for (int k = 0; k < 200; ++k) line.emplace_back(3.0f * k, 20.0f + 2.0f * k);
  const SearchResult& on_line = search.run(line, kImage, always);
  EXPECT_EQ(on_line.dynamic_count, 200);

  // A single point, and many copies of one point (hull of one vertex), both on path nodes
  // (fixed lanes at y = 24 + 48 k, nodes at x = 8 + 16 k).
  AntColonyParams fixed_lanes;
  fixed_lanes.lane_spacing_px = 48.0f;
  fixed_lanes.alternate_lanes = false;
  DynamicPointSearch on_nodes(fixed_lanes);
  const std::vector<Eigen::Vector2f> one = {{104.0f, 72.0f}};
  EXPECT_EQ(on_nodes.run(one, kImage, always).dynamic_count, 1);
  const std::vector<Eigen::Vector2f> copies(50, Eigen::Vector2f(296.0f, 120.0f));
  EXPECT_EQ(on_nodes.run(copies, kImage, always).dynamic_count, 50);
  EXPECT_EQ(on_nodes.run({}, kImage, always).tested_count, 0);

  // A round cap is honoured even when every round finds something.
  AntColonyParams capped;
  capped.max_band_rounds = 3;
  capped.band_width_px = 5.0f;
  DynamicPointSearch small_rounds(capped);
  const SearchResult& c = small_rounds.run(line, kImage, always);
  EXPECT_LE(c.band_rounds, 3 * c.communities);
}

TEST(AntColonySearch, PriorityPointsSeedCommunities) {
  // A lone dynamic cluster between lanes is missed by the path but found from a priority seed
  // (the previous frame's mask warped by the compensated homography).
  std::vector<Eigen::Vector2f> points;
  std::vector<int> dynamic_ids;
  for (int k = 0; k < 10; ++k) {
    points.emplace_back(300.0f + 2.0f * k, 48.0f);  // exactly between lanes at y=24 and y=72
    dynamic_ids.push_back(k);
  }
  const auto is_dynamic = [](int i) { return i < 10; };
  AntColonyParams fixed_lanes;
  fixed_lanes.lane_spacing_px = 48.0f;
  fixed_lanes.alternate_lanes = false;
  DynamicPointSearch search(fixed_lanes);
  EXPECT_EQ(search.run(points, kImage, is_dynamic).dynamic_count, 0);
  const std::vector<int> priority = {4};
  EXPECT_EQ(search.run(points, kImage, is_dynamic, priority).dynamic_count, 10);
}

TEST(AntColonySearch, CountsTheTestsOfTheLastEmptyBand) {
  // Ten dynamic points in a row (x 300..318) seeded from a priority point at x = 300. Round 1's
  // band (dZ = 80 px around x = 300) holds the row; round 2's band around the row's hull reaches
  // the 4 static points at x = 388 (88 px from the seed, 70 px from the hull) and finds nothing,
  // so it is the last band and made exactly those 4 tests. Points at x = 500 are never tested.
  std::vector<Eigen::Vector2f> points;
  for (int k = 0; k < 10; ++k) points.emplace_back(300.0f + 2.0f * k, 48.0f);
  for (int k = 0; k < 4; ++k) points.emplace_back(388.0f, 40.0f + 5.0f * k);
  for (int k = 0; k < 4; ++k) points.emplace_back(500.0f, 40.0f + 5.0f * k);
  const auto is_dynamic = [](int i) { return i < 10; };
  AntColonyParams fixed_lanes;
  fixed_lanes.lane_spacing_px = 48.0f;  // lanes at y = 24, 72, ...: the path misses y = 40..55
  fixed_lanes.alternate_lanes = false;
  DynamicPointSearch search(fixed_lanes);
  const std::vector<int> priority = {0};
  const SearchResult& result = search.run(points, kImage, is_dynamic, priority);
  EXPECT_EQ(result.dynamic_count, 10);
  EXPECT_EQ(result.tested_count, 14);
  EXPECT_EQ(result.communities, 1);
  EXPECT_EQ(result.band_rounds, 2);
  EXPECT_EQ(result.last_band_tests, 4);
}

TEST(AntColonySearch, AlternateRunsShiftTheLanesByHalfASpacing) {
  // A short cluster exactly between two lanes of phase 0 lies on a lane of phase 1, so a mover
  // the path passes by in one frame is found in the next one.
  AntColonyParams params;
  params.lane_spacing_px = 96.0f;
  params.search_radius_px = 12.0f;
  std::vector<Eigen::Vector2f> points;
  for (int k = 0; k < 10; ++k) points.emplace_back(300.0f + 2.0f * k, 96.0f);  // lanes 48, 144
  const auto always = [](int) { return true; };
  DynamicPointSearch search(params);
  EXPECT_EQ(search.run(points, kImage, always).dynamic_count, 0);
  EXPECT_EQ(search.run(points, kImage, always).dynamic_count, 10);  // phase 1: lane at y = 96
  EXPECT_EQ(search.run(points, kImage, always).dynamic_count, 0);
  params.alternate_lanes = false;
  DynamicPointSearch fixed(params);
  EXPECT_EQ(fixed.run(points, kImage, always).dynamic_count, 0);
  EXPECT_EQ(fixed.run(points, kImage, always).dynamic_count, 0);
}

TEST(ConvexHull, DegenerateAndDistance) {
  std::vector<Eigen::Vector2f> scratch, hull;
  const std::vector<Eigen::Vector2f> square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}, {5, 5}, {5, 0}};
  convex_hull(square, scratch, hull);
  EXPECT_EQ(hull.size(), 4u);
  EXPECT_FLOAT_EQ(distance_to_convex_hull(hull, {5, 5}), 0.0f);
  EXPECT_FLOAT_EQ(distance_to_convex_hull(hull, {13, 14}), 5.0f);
  const std::vector<Eigen::Vector2f> line = {{0, 0}, {1, 1}, {2, 2}, {3, 3}};
  convex_hull(line, scratch, hull);
  EXPECT_EQ(hull.size(), 2u);
  EXPECT_NEAR(distance_to_convex_hull(hull, {0, 2}), std::sqrt(2.0f), 1e-6);
}

TEST(AntColonySearch, ParamsFromYaml) {
  const YAML::Node node = YAML::Load("strategy: exhaustive\nsearch_radius_px: 10\n");
  YamlSection section(node, "c.yaml", "geometry.search");
  const AntColonyParams p = AntColonyParams::from_yaml(section);
  EXPECT_EQ(p.strategy, SearchStrategy::exhaustive);
  EXPECT_FLOAT_EQ(p.search_radius_px, 10.0f);
  const YAML::Node bad = YAML::Load("strategy: random\n");
  YamlSection bad_section(bad, "c.yaml", "geometry.search");
  try {
    AntColonyParams::from_yaml(bad_section);
    FAIL() << "expected Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "c.yaml:1: key 'geometry.search.strategy' must be ant_colony or exhaustive, not "
                 "'random'");
  }
  const YAML::Node zero = YAML::Load("band_width_px: 0\n");
  YamlSection zero_section(zero, "c.yaml", "geometry.search");
  EXPECT_THROW(AntColonyParams::from_yaml(zero_section), Error);
}

}  // namespace
}  // namespace pspslam
