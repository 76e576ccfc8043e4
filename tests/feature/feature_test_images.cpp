#include "feature_test_images.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace pspslam::testing {

cv::Mat make_textured_image(int width, int height, unsigned seed) {
  cv::RNG rng(seed);  // cv::RNG is fully specified: same image on every machine
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(128));
  const int n_shapes = width * height / 600;
  for (int i = 0; i < n_shapes; ++i) {
    const cv::Point center(rng.uniform(0, width), rng.uniform(0, height));
    const int extent = rng.uniform(3, 40);
    const cv::Scalar grey(rng.uniform(0, 256));
    switch (rng.uniform(0, 3)) {
      case 0:
        cv::rectangle(image, center, center + cv::Point(extent, rng.uniform(3, 40)), grey,
                      cv::FILLED);
        break;
      case 1:
        cv::ellipse(image, center, cv::Size(extent, rng.uniform(2, 20)), rng.uniform(0.0, 180.0),
                    0.0, 360.0, grey, cv::FILLED);
        break;
      default:
        cv::line(image, center, center + cv::Point(rng.uniform(-40, 40), rng.uniform(-40, 40)),
                 grey, rng.uniform(1, 4));
        break;
    }
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  return image;
}

cv::Mat load_bonn_gray_frame(const std::filesystem::path& shared, int index) {
  const std::filesystem::path folder = shared / "data" / "bonn_crowd_dev" / "rgb";
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() == ".jpg") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  if (index < 0 || index >= static_cast<int>(files.size())) {
    throw std::runtime_error("no frame " + std::to_string(index) + " in " + folder.string());
  }
  cv::Mat gray = cv::imread(files[index].string(), cv::IMREAD_GRAYSCALE);
  if (gray.empty()) throw std::runtime_error("cannot read " + files[index].string());
  return gray;
}

}  // namespace pspslam::testing
