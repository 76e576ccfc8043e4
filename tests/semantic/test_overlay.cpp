#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "pspslam/core/error.h"
#include "pspslam/semantic/overlay.h"

namespace pspslam {
namespace {

const std::vector<std::string> kNames = {
    "background", "aeroplane", "bicycle",     "bird", "boat",  "bottle",    "bus",   "car",
    "cat",        "chair",     "diningtable", "dog",  "horse", "motorbike", "person"};
constexpr int kPerson = 14, kChair = 9, kBottle = 5;
const std::vector<int> kDynamic = {1, 2, 3, 4, 6, 7, 8, 11, 12, 13, kPerson};

int saturation(const cv::Vec3b& bgr) {
  cv::Mat pixel(1, 1, CV_8UC3, cv::Scalar(bgr[0], bgr[1], bgr[2])), hsv;
  cv::cvtColor(pixel, hsv, cv::COLOR_BGR2HSV);
  return hsv.at<cv::Vec3b>(0, 0)[1];
}

// Grey image; a person on the lower left, a chair on the lower right, the legend's corner free.
struct Scene {
  cv::Mat bgr = cv::Mat(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  LabelMap labels = LabelMap(240, 320, CV_8UC1, cv::Scalar(0));
  Scene() {
    labels(cv::Rect(20, 120, 100, 100)).setTo(kPerson);
    labels(cv::Rect(200, 120, 100, 100)).setTo(kChair);
  }
};

TEST(Overlay, DynamicClassesStrongStaticMuted) {
  const Scene s;
  const cv::Mat out = overlay_segmentation(s.bgr, s.labels, kDynamic, kNames);
  const cv::Vec3b person = out.at<cv::Vec3b>(170, 70), chair = out.at<cv::Vec3b>(170, 250);
  // Person: 60 % of pure red over grey 128 = (51, 51, 204): saturated and red.
  EXPECT_NEAR(person[0], 51, 1);
  EXPECT_NEAR(person[1], 51, 1);
  EXPECT_NEAR(person[2], 204, 1);
  EXPECT_GT(saturation(person), 180);
  // Chair: VOC red (0,0,192) pulled 65 % to its grey 64, blended at 30 %: nearly the grey input.
  EXPECT_LT(saturation(chair), 50);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(chair[k], 128, 30) << k;
  EXPECT_GT(chair[2], chair[0]);  // still a hint of the class hue
  // Background untouched.
  EXPECT_EQ(out.at<cv::Vec3b>(60, 300), cv::Vec3b(128, 128, 128));
}

TEST(Overlay, OutlinesDynamicRegionsOnly) {
  const Scene s;
  const cv::Mat out = overlay_segmentation(s.bgr, s.labels, kDynamic, kNames);
  // The person's border pixels (and the pixel just outside) carry the full class colour.
  const cv::Vec3b red(0, 0, 255);
  for (const cv::Point p : {cv::Point(20, 170), cv::Point(119, 170), cv::Point(70, 120),
                            cv::Point(70, 219), cv::Point(19, 170)}) {
    EXPECT_EQ(out.at<cv::Vec3b>(p), red) << p;
  }
  // Inside, away from the border, it is the blend, not the outline colour.
  EXPECT_NE(out.at<cv::Vec3b>(170, 70), red);
  // The chair's border looks like its interior: no outline on static classes.
  EXPECT_EQ(out.at<cv::Vec3b>(170, 200), out.at<cv::Vec3b>(170, 250));
  EXPECT_EQ(out.at<cv::Vec3b>(170, 199), cv::Vec3b(128, 128, 128));
}

TEST(Overlay, LegendListsOnlyClassesPresentDynamicFirst) {
  Scene s;
  s.labels(cv::Rect(260, 40, 10, 10)).setTo(kBottle);  // a small static object, clear of the box
  const auto entries = overlay_legend_entries(s.labels, kDynamic, kNames);
  ASSERT_EQ(entries.size(), 3u);
  EXPECT_EQ(entries[0].label, "person (dynamic)");
  EXPECT_EQ(entries[0].colour, cv::Vec3b(0, 0, 255));
  EXPECT_EQ(entries[1].label, "chair");  // 10000 pixels before the bottle's 100
  EXPECT_EQ(entries[2].label, "bottle");
  EXPECT_EQ(entries[1].colour, overlay_class_colour(kChair, kDynamic, kNames));

  // Drawn into the top-left corner of the overlay: dark box, white text, the swatches' colours.
  const cv::Mat out = overlay_segmentation(s.bgr, s.labels, kDynamic, kNames);
  cv::Mat canvas = s.bgr.clone();
  const cv::Rect box = draw_legend(canvas, entries);
  EXPECT_EQ(box.x, 8);
  EXPECT_EQ(box.y, 8);
  EXPECT_EQ(box.height, 6 + 3 * 20 + 3);
  EXPECT_GT(box.width, 60);
  const cv::Mat legend = out(box);
  EXPECT_EQ(cv::norm(legend, canvas(box), cv::NORM_INF), 0.0);  // same helper, same pixels
  cv::Mat white, red;
  cv::inRange(legend, cv::Scalar(200, 200, 200), cv::Scalar(255, 255, 255), white);
  cv::inRange(legend, cv::Scalar(0, 0, 250), cv::Scalar(5, 5, 255), red);
  EXPECT_GT(cv::countNonZero(white), 100);    // text and swatch frames
  EXPECT_GE(cv::countNonZero(red), 12 * 12);  // the person swatch
  // Semi-opaque: the grey 128 under the box is darkened to 45, not replaced.
  EXPECT_EQ(legend.at<cv::Vec3b>(1, box.width - 2), cv::Vec3b(45, 45, 45));
  // Outside the box nothing changed.
  EXPECT_EQ(canvas.at<cv::Vec3b>(box.y + box.height + 1, box.x), cv::Vec3b(128, 128, 128));
  // Nothing to list, nothing drawn.
  cv::Mat untouched = s.bgr.clone();
  EXPECT_TRUE(draw_legend(untouched, {}).empty());
  EXPECT_EQ(cv::norm(untouched, s.bgr, cv::NORM_INF), 0.0);
}

TEST(Overlay, OtherDynamicClassesGetDistinctVividColours) {
  const cv::Vec3b car = overlay_class_colour(7, kDynamic, kNames);
  const cv::Vec3b dog = overlay_class_colour(11, kDynamic, kNames);
  EXPECT_NE(car, dog);
  EXPECT_NE(car, cv::Vec3b(0, 0, 255));
  EXPECT_EQ(saturation(car), 255);
  EXPECT_EQ(saturation(dog), 255);
}

TEST(Overlay, RejectsMismatchedInputs) {
  const Scene s;
  try {
    overlay_segmentation(s.bgr, s.labels(cv::Rect(0, 0, 10, 10)).clone(), kDynamic, kNames);
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "overlay_segmentation: expected a CV_8UC3 image and a CV_8UC1 label map of its "
                 "size");
  }
}

}  // namespace
}  // namespace pspslam
