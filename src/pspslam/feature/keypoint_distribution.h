#pragma once

#include <opencv2/core/types.hpp>

#include <span>
#include <vector>

namespace pspslam {

// Picks an evenly spread subset of keypoints with a quadtree (the ORB-SLAM2 scheme): the area is
// split into quadrants, recursively, only where a node holds more than one keypoint, until there
// are as many non-empty nodes as keypoints wanted (or no node can be split); each node then keeps
// its strongest keypoint. Plain "best N by response" would cluster all features on the few most
// textured objects, which makes pose estimation ill-conditioned.
//
// The object only owns scratch buffers, reused from call to call so that extraction does not
// allocate per frame once warmed up.
class QuadtreeDistributor {
 public:
  // Writes at most `target` of `candidates` to `selected` (cleared first; its capacity is reused).
  // `area` must contain every candidate position (x in [area.x, area.x + area.width), same for y).
  // Ties in response are broken by candidate order, so the result is deterministic.
  void distribute(std::span<const cv::KeyPoint> candidates, const cv::Rect2f& area, int target,
                  std::vector<cv::KeyPoint>& selected);

 private:
  struct Node {
    float min_x = 0.0f;
    float min_y = 0.0f;
    float max_x = 0.0f;
    float max_y = 0.0f;
    int begin = 0;  // range [begin, end) in candidate_order_
    int end = 0;

    int count() const { return end - begin; }
  };

  bool can_split(const Node& node) const;
  // Splits `node` into its non-empty quadrants (1 to 4), written to `children`; returns how many.
  int split(const Node& node, std::span<const cv::KeyPoint> candidates, Node* children);

  std::vector<int> candidate_order_;
  std::vector<Node> nodes_;
  std::vector<Node> next_nodes_;
  std::vector<int> split_order_;
};

// Per-level feature budgets when some levels cannot fill their share: budgets[l] starts at
// min(shares[l], available[l]), and what the short levels leave unused goes to the levels that
// still have candidates to spare, in proportion to their shares (water-filling), so the total is
// min(sum of shares, sum of available). A level never gets more than it has. All three spans have
// the same length; deterministic, no allocation.
void share_feature_budget(std::span<const int> shares, std::span<const int> available,
                          std::span<int> budgets);

}  // namespace pspslam
