#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

namespace pspslam {

// Fusion of the two dynamic verdicts for one frame: a keypoint is dynamic when it lies
// on the (dilated) semantic mask of an a-priori dynamic class, or when the geometry stage flagged
// it (tested dynamic, or inside a region grown from dynamic points -- which is how objects of
// static classes that move, e.g. a carried box, become dynamic).
//
// `semantic_mask`: CV_8UC1, non-zero = dynamic, may be empty. `geometry_dynamic`: one flag per
// keypoint, or empty. Writes one flag per keypoint into `dynamic` (resized, no other allocation)
// and returns how many are dynamic.
int fuse_keypoint_flags(std::span<const cv::KeyPoint> keypoints, const cv::Mat& semantic_mask,
                        std::span<const std::uint8_t> geometry_dynamic,
                        std::vector<std::uint8_t>& dynamic);

// Removes the flagged keypoints (and their descriptor rows) in place, keeping the order of the
// others. Dynamic features must neither be tracked nor create map points, so they are dropped
// before the Frame exists. Returns the number removed.
int remove_flagged_keypoints(std::span<const std::uint8_t> dynamic,
                             std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors);

// The semantic mask as the ORB extractor wants it: grown by `margin_px` (elliptic) so that corners
// on a silhouette -- half person, half background -- are not extracted either. Empty in, empty out.
cv::Mat dilate_mask(const cv::Mat& mask, int margin_px);

}  // namespace pspslam
