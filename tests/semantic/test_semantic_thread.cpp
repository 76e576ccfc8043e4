#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <future>
#include <mutex>
#include <thread>

#include "pspslam/core/error.h"
#include "pspslam/core/thread_priority.h"
#include "pspslam/semantic/semantic_thread.h"

namespace pspslam {
namespace {

using namespace std::chrono_literals;

// Frame `id` is an image whose pixels all hold id % 256; the fake segmenter returns that
// value as the label of every pixel, so each published label map names its frame.
cv::Mat frame_image(std::int64_t id) {
  return cv::Mat(24, 32, CV_8UC3, cv::Scalar::all(static_cast<double>(id % 256)));
}

// A deliberately slow segmenter: sleeps `delay` per frame, or, when gated, waits until the
// test opens the gate (so the tests control exactly which frame is being processed).
class FakeSegmenter : public Segmenter {
 public:
  struct Control {
    std::mutex mutex;
    std::condition_variable cv;
    bool gated = false;
    bool open = false;
    int entered = 0;  // frames whose segmentation started
    std::vector<int> seen;
  };

  FakeSegmenter(std::shared_ptr<Control> control, std::chrono::milliseconds delay)
      : control_(std::move(control)), delay_(delay) {}

  LabelMap segment(const cv::Mat& bgr) override {
    {
      std::unique_lock lock(control_->mutex);
      ++control_->entered;
      control_->seen.push_back(bgr.at<cv::Vec3b>(0, 0)[0]);
      control_->cv.notify_all();
      control_->cv.wait(lock, [&] { return !control_->gated || control_->open; });
      if (control_->gated) control_->open = false;  // one frame per opening
    }
    std::this_thread::sleep_for(delay_);
    return LabelMap(bgr.size(), CV_8UC1, cv::Scalar(bgr.at<cv::Vec3b>(0, 0)[0]));
  }
  const std::vector<std::string>& class_names() const override { return names_; }
  std::vector<int> default_dynamic_classes() const override { return {15}; }

 private:
  std::shared_ptr<Control> control_;
  std::chrono::milliseconds delay_;
  std::vector<std::string> names_ = [] {
    std::vector<std::string> n(256);
    for (int i = 0; i < 256; ++i) {
      std::string name = "c";
      name += std::to_string(i);
      n[static_cast<size_t>(i)] = name;
    }
    n[15] = "person";
    return n;
  }();
};

void wait_entered(FakeSegmenter::Control& c, int count) {
  std::unique_lock lock(c.mutex);
  ASSERT_TRUE(c.cv.wait_for(lock, 5s, [&] { return c.entered >= count; }));
}

void open_gate(FakeSegmenter::Control& c) {
  std::lock_guard lock(c.mutex);
  c.open = true;
  c.cv.notify_all();
}

TEST(SemanticThread, ProducerNeverBlocksAndResultsMatchTheirFrames) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  SemanticParams params;
  params.history = 1000;
  SemanticThread thread(std::make_unique<FakeSegmenter>(control, 40ms), params);

  // 60 frames at ~400 Hz against a 40 ms segmenter: nearly all must be dropped, none may wait.
  double slowest_submit_ms = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::int64_t id = 1; id <= 60; ++id) {
    const auto s = std::chrono::steady_clock::now();
    ASSERT_TRUE(thread.submit(id, 0.5 * static_cast<double>(id), frame_image(id)));
    slowest_submit_ms = std::max(
        slowest_submit_ms,
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - s).count());
    std::this_thread::sleep_for(2500us);
  }
  const double producer_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  // Submitting is a queue operation: far below one 40 ms inference even on a loaded machine.
  EXPECT_LT(slowest_submit_ms, 40.0);

  thread.wait_idle();
  const SemanticStats stats = thread.stats();
  EXPECT_EQ(stats.submitted, 60);
  EXPECT_EQ(stats.processed + stats.dropped, 60);
  // At most one frame per 40 ms inference (+ the last one) can have been processed.
  EXPECT_LE(stats.processed, static_cast<std::int64_t>(producer_ms / 40.0) + 2);
  EXPECT_GT(stats.dropped, 0);

  // Published in increasing order, the newest frame always processed, each result its frame's.
  std::int64_t previous = 0;
  int published = 0;
  for (std::int64_t id = 1; id <= 60; ++id) {
    const auto r = thread.find(0.5 * static_cast<double>(id));
    if (!r) continue;
    ++published;
    EXPECT_GT(r->frame_id, previous);
    previous = r->frame_id;
    EXPECT_EQ(r->frame_id, id);
    EXPECT_DOUBLE_EQ(r->timestamp, 0.5 * static_cast<double>(id));
    EXPECT_EQ(cv::countNonZero(r->labels != static_cast<int>(id % 256)), 0);
    EXPECT_GE(r->latency_ms, r->inference_ms);
    EXPECT_GE(r->inference_ms, 35.0);
  }
  EXPECT_EQ(published, stats.processed);
  ASSERT_NE(thread.newest(), nullptr);
  EXPECT_EQ(thread.newest()->frame_id, 60);
}

TEST(SemanticThread, KeepsOnlyTheLatestPendingFrame) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  control->gated = true;
  SemanticThread thread(std::make_unique<FakeSegmenter>(control, 0ms), SemanticParams{});

  thread.submit(1, 1.0, frame_image(1));
  wait_entered(*control, 1);  // frame 1 is being segmented
  for (std::int64_t id = 2; id <= 5; ++id)
    thread.submit(id, static_cast<double>(id), frame_image(id));
  EXPECT_EQ(thread.stats().dropped, 3);        // 2, 3, 4 replaced by 5
  EXPECT_EQ(thread.wait_for(3, 1s), nullptr);  // dropped: answered at once, not after 1 s
  open_gate(*control);
  wait_entered(*control, 2);
  open_gate(*control);
  const auto r5 = thread.wait_for(5, 5s);
  ASSERT_NE(r5, nullptr);
  EXPECT_EQ(r5->labels.at<uchar>(3, 4), 5);
  thread.wait_idle();
  EXPECT_EQ(control->seen, (std::vector<int>{1, 5}));
  ASSERT_NE(thread.find(1.0), nullptr);
  EXPECT_EQ(thread.find(2.0), nullptr);
  EXPECT_EQ(thread.find(4.0), nullptr);
  EXPECT_EQ(thread.find(5.00001, 1e-3)->frame_id, 5);
}

TEST(SemanticThread, QueueSizeBoundsThePendingFrames) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  control->gated = true;
  SemanticParams params;
  params.queue_size = 2;
  SemanticThread thread(std::make_unique<FakeSegmenter>(control, 0ms), params);
  thread.submit(1, 1.0, frame_image(1));
  wait_entered(*control, 1);
  for (std::int64_t id = 2; id <= 6; ++id)
    thread.submit(id, static_cast<double>(id), frame_image(id));
  for (int i = 0; i < 3; ++i) {
    open_gate(*control);
    if (i < 2) wait_entered(*control, i + 2);
  }
  thread.wait_idle();
  EXPECT_EQ(control->seen, (std::vector<int>{1, 5, 6}));
  EXPECT_EQ(thread.stats().dropped, 3);
}

TEST(SemanticThread, ShutdownWithPendingWorkFinishesTheRunningFrameAndDropsTheRest) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  control->gated = true;
  auto thread = std::make_unique<SemanticThread>(std::make_unique<FakeSegmenter>(control, 0ms),
                                                 SemanticParams{});
  thread->submit(1, 1.0, frame_image(1));
  wait_entered(*control, 1);
  thread->submit(2, 2.0, frame_image(2));

  auto stopping = std::async(std::launch::async, [&] { thread->stop(); });
  EXPECT_EQ(stopping.wait_for(100ms), std::future_status::timeout);  // frame 1 still running
  EXPECT_FALSE(thread->submit(3, 3.0, frame_image(3)));              // no new work accepted
  open_gate(*control);
  ASSERT_EQ(stopping.wait_for(5s), std::future_status::ready);
  EXPECT_EQ(control->seen, (std::vector<int>{1}));
  ASSERT_NE(thread->newest(), nullptr);
  EXPECT_EQ(thread->newest()->frame_id, 1);
  EXPECT_EQ(thread->wait_for(2, 1s), nullptr);
  EXPECT_EQ(thread->stats().dropped, 1);
  const auto t0 = std::chrono::steady_clock::now();
  thread.reset();  // destructor after stop(): returns at once
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 1s);
}

TEST(SemanticThread, DestructorJoinsWhilePendingFramesWait) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  {
    SemanticThread thread(std::make_unique<FakeSegmenter>(control, 30ms), SemanticParams{});
    for (std::int64_t id = 1; id <= 5; ++id)
      thread.submit(id, static_cast<double>(id), frame_image(id));
  }  // must not hang nor crash
  std::lock_guard lock(control->mutex);
  EXPECT_LE(control->entered, 2);
}

TEST(SemanticThread, RejectsNonIncreasingIdsAndUnknownDynamicClasses) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  SemanticThread thread(std::make_unique<FakeSegmenter>(control, 0ms), SemanticParams{});
  thread.submit(7, 0.0, frame_image(7));
  try {
    thread.submit(7, 0.1, frame_image(7));
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "SemanticThread::submit: frame id 7 is not greater than the previous one (7)");
  }
  SemanticParams params;
  params.dynamic_classes = {"person", "unicorn"};
  try {
    SemanticThread bad(std::make_unique<FakeSegmenter>(control, 0ms), params);
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("semantic.dynamic_classes: unknown class 'unicorn'"),
              std::string::npos)
        << e.what();
  }
}

class ThrowingSegmenter : public FakeSegmenter {
 public:
  using FakeSegmenter::FakeSegmenter;
  LabelMap segment(const cv::Mat& bgr) override {
    if (bgr.at<cv::Vec3b>(0, 0)[0] == 2) throw Error("frame 2 is broken");
    return FakeSegmenter::segment(bgr);
  }
};

TEST(SemanticThread, AFailingFrameIsReportedAndTheThreadGoesOn) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  SemanticThread thread(std::make_unique<ThrowingSegmenter>(control, 0ms), SemanticParams{});
  thread.submit(2, 2.0, frame_image(2));
  EXPECT_EQ(thread.wait_for(2, 5s), nullptr);
  thread.submit(3, 3.0, frame_image(3));
  ASSERT_NE(thread.wait_for(3, 5s), nullptr);
  const SemanticStats stats = thread.stats();
  EXPECT_EQ(stats.failed, 1);
  EXPECT_EQ(stats.processed, 1);
  EXPECT_EQ(stats.last_error, "frame 2 is broken");
}

// Records the nice value of the thread that segments.
class NiceRecordingSegmenter : public FakeSegmenter {
 public:
  NiceRecordingSegmenter(std::shared_ptr<Control> control, std::atomic<int>& nice)
      : FakeSegmenter(std::move(control), 0ms), nice_(nice) {}
  LabelMap segment(const cv::Mat& bgr) override {
    nice_ = this_thread_nice();
    return FakeSegmenter::segment(bgr);
  }

 private:
  std::atomic<int>& nice_;
};

TEST(SemanticThread, SegmentsAtTheRequestedLowerPriority) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  std::atomic<int> nice{-100};
  SemanticParams params;
  params.thread_nice = 4;
  SemanticThread thread(std::make_unique<NiceRecordingSegmenter>(control, nice), params);
  thread.submit(1, 1.0, frame_image(1));
  ASSERT_NE(thread.wait_for(1, 5s), nullptr);
  EXPECT_EQ(nice.load(), std::min(19, this_thread_nice() + 4));
}

TEST(SemanticThread, AnInjectedDelayCountsAsInference) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  SemanticParams params;
  params.injected_delay = {60, 60};
  SemanticThread thread(std::make_unique<FakeSegmenter>(control, 0ms), params);
  thread.submit(1, 1.0, frame_image(1));
  const auto result = thread.wait_for(1, 5s);
  ASSERT_NE(result, nullptr);
  EXPECT_GE(result->inference_ms, 60.0);  // a sleep lasts at least as long as asked
  EXPECT_EQ(cv::countNonZero(result->labels != 1), 0);
}

// Labels every pixel with `label`, so a result says which of a thread's segmenters made it.
class ConstantSegmenter : public FakeSegmenter {
 public:
  ConstantSegmenter(std::shared_ptr<Control> control, int label)
      : FakeSegmenter(std::move(control), 0ms), label_(label) {}
  LabelMap segment(const cv::Mat& bgr) override {
    FakeSegmenter::segment(bgr);
    return LabelMap(bgr.size(), CV_8UC1, cv::Scalar(label_));
  }

 private:
  int label_;
};

TEST(SemanticThread, APaceTooSlowForTheBudgetStepsDownToTheSmallerNetworkAndSparserFrames) {
  auto control = std::make_shared<FakeSegmenter::Control>();
  SemanticParams params;
  params.injected_delay = {40, 40};  // far over the 2 x 1 ms budget
  params.dynamic_classes = {"person", "c12"};
  SemanticPaceParams pace;
  pace.frame_period_ms = 1.0;
  pace.results_to_step_down = 1;
  std::vector<std::unique_ptr<Segmenter>> segmenters;
  segmenters.push_back(std::make_unique<ConstantSegmenter>(control, 15));
  segmenters.push_back(std::make_unique<ConstantSegmenter>(control, 12));
  SemanticThread thread(std::move(segmenters), params,
                        SemanticPace(pace, pace_ladder(2, 2), {2.0, 1.0}));
  EXPECT_EQ(thread.stride(), 1);
  for (std::int64_t id = 1; id <= 3; ++id) {
    thread.submit(id, static_cast<double>(id), frame_image(id));
    const auto result = thread.wait_for(id, 5s);
    ASSERT_NE(result, nullptr);
    EXPECT_EQ(result->level, id - 1);
    // Level 0 runs the first segmenter (person = 15), levels 1 and 2 the second (dog = 12).
    EXPECT_EQ(result->labels.at<uchar>(0, 0), id == 1 ? 15 : 12);
    EXPECT_EQ(cv::countNonZero(result->dynamic_mask), result->labels.rows * result->labels.cols);
  }
  thread.wait_idle();
  EXPECT_EQ(thread.stride(), 2);
  const SemanticStats stats = thread.stats();
  EXPECT_EQ(stats.level, 2);
  EXPECT_EQ(stats.level_changes, 2);
  EXPECT_EQ(stats.processed_per_level, (std::vector<std::int64_t>{1, 1, 1}));
}

TEST(DynamicMask, MarksDynamicLabelsAndGrowsByTheMargin) {
  LabelMap labels(40, 50, CV_8UC1, cv::Scalar(0));
  labels(cv::Rect(10, 10, 5, 5)).setTo(15);  // person
  labels(cv::Rect(30, 20, 4, 4)).setTo(9);   // chair: static
  labels(cv::Rect(40, 30, 3, 3)).setTo(12);  // dog
  const cv::Mat m0 = dynamic_mask(labels, {15, 12});
  EXPECT_EQ(cv::countNonZero(m0), 25 + 9);
  EXPECT_EQ(m0.at<uchar>(12, 12), 255);
  EXPECT_EQ(m0.at<uchar>(21, 31), 0);
  const cv::Mat m2 = dynamic_mask(labels, {15}, 2);
  EXPECT_EQ(m2.at<uchar>(12, 8), 255);  // 2 px left of the person
  EXPECT_EQ(m2.at<uchar>(12, 7), 0);    // 3 px: outside the margin
  EXPECT_EQ(m2.at<uchar>(8, 12), 255);
  EXPECT_EQ(m2.at<uchar>(31, 41), 0);  // dog not in this set
}

}  // namespace
}  // namespace pspslam
