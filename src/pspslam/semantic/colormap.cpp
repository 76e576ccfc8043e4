#include <opencv2/imgproc.hpp>

#include "pspslam/core/error.h"
#include "pspslam/semantic/segmenter.h"

namespace pspslam {

cv::Vec3b label_color(int id) {
  // PASCAL VOC palette: the bits of the id spread over the high bits of R, G and B.
  int r = 0, g = 0, b = 0;
  for (int shift = 7; shift >= 0 && id > 0; --shift, id >>= 3) {
    r |= (id & 1) << shift;
    g |= ((id >> 1) & 1) << shift;
    b |= ((id >> 2) & 1) << shift;
  }
  return cv::Vec3b(static_cast<uchar>(b), static_cast<uchar>(g), static_cast<uchar>(r));
}

cv::Mat overlay_labels(const cv::Mat& bgr, const LabelMap& labels, double alpha) {
  if (bgr.type() != CV_8UC3 || labels.type() != CV_8UC1 || bgr.size() != labels.size()) {
    throw Error("overlay_labels: expected a CV_8UC3 image and a CV_8UC1 label map of its size");
  }
  cv::Vec3b palette[256];
  for (int i = 0; i < 256; ++i) palette[i] = label_color(i);
  cv::Mat out = bgr.clone();
  for (int y = 0; y < out.rows; ++y) {
    const uchar* l = labels.ptr<uchar>(y);
    cv::Vec3b* p = out.ptr<cv::Vec3b>(y);
    for (int x = 0; x < out.cols; ++x) {
      if (l[x] == 0) continue;
      const cv::Vec3b c = palette[l[x]];
      for (int k = 0; k < 3; ++k) {
        p[x][k] = cv::saturate_cast<uchar>((1.0 - alpha) * p[x][k] + alpha * c[k]);
      }
    }
  }
  return out;
}

}  // namespace pspslam
