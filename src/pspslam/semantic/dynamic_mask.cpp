#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "pspslam/core/error.h"
#include "pspslam/semantic/segmenter.h"

namespace pspslam {

cv::Mat dynamic_mask(const LabelMap& labels, const std::vector<int>& dynamic_ids, int dilation_px) {
  if (labels.type() != CV_8UC1) throw Error("dynamic_mask: labels must be CV_8UC1");
  cv::Mat table(1, 256, CV_8U, cv::Scalar(0));
  for (int id : dynamic_ids) {
    if (id >= 0 && id < 256) table.at<uchar>(id) = 255;
  }
  cv::Mat mask;
  cv::LUT(labels, table, mask);
  if (dilation_px > 0) {
    const cv::Mat kernel = cv::getStructuringElement(
        cv::MORPH_ELLIPSE, cv::Size(2 * dilation_px + 1, 2 * dilation_px + 1));
    cv::dilate(mask, mask, kernel);
  }
  return mask;
}

std::vector<int> class_ids(const std::vector<std::string>& class_names,
                           const std::vector<std::string>& names, const std::string& context) {
  std::vector<int> ids;
  ids.reserve(names.size());
  for (const std::string& name : names) {
    const auto it = std::find(class_names.begin(), class_names.end(), name);
    if (it == class_names.end()) {
      std::string known;
      for (const std::string& c : class_names) {
        if (!known.empty()) known += ", ";
        known += c;
      }
      throw Error(context + ": unknown class '" + name + "' (classes: " + known + ")");
    }
    ids.push_back(static_cast<int>(it - class_names.begin()));
  }
  return ids;
}

}  // namespace pspslam
