#include <opencv2/imgproc.hpp>

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

}  // namespace pspslam
