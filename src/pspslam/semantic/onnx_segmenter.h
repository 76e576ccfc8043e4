#pragma once

#include <opencv2/dnn.hpp>

#include <chrono>
#include <filesystem>
#include <memory>

#include "pspslam/semantic/segmenter.h"
#include "pspslam/semantic/segmenter_metadata.h"

namespace pspslam {

// A segmentation network in ONNX run by OpenCV DNN (CPU), configured entirely by its
// metadata: our PSPNet and the DeepLab / ESPNet teachers go through this same class.
// The image is stretched to the network input (bilinear), normalised per channel, and the
// arg-max over the logits is resized back to the image with nearest neighbour.
// Not thread-safe (cv::dnn::Net is stateful); the CPU thread count is OpenCV's global
// setting (cv::setNumThreads), left to the application.
class OnnxSegmenter : public Segmenter {
 public:
  explicit OnnxSegmenter(SegmenterMetadata metadata);
  static std::unique_ptr<OnnxSegmenter> from_file(const std::filesystem::path& metadata_file);

  LabelMap segment(const cv::Mat& bgr) override;
  const std::vector<std::string>& class_names() const override { return meta_.classes; }
  std::vector<int> default_dynamic_classes() const override;

  // Raw network output for `bgr` (1 x classes x h x w, CV_32F), valid until the next call.
  const cv::Mat& logits(const cv::Mat& bgr);
  // The input blob (1 x 3 x H x W, CV_32F) the last call fed to the network.
  const cv::Mat& last_input() const { return blob_; }

  const SegmenterMetadata& metadata() const { return meta_; }

  // Wall time of the stages of the last segment() call (profiling; two clock reads per stage).
  struct StageTimes {
    double preprocess_ms = 0;   // resize + normalisation into the blob
    double network_ms = 0;      // setInput + forward
    double postprocess_ms = 0;  // arg-max + label resize to the image
  };
  const StageTimes& last_stage_times() const { return stage_times_; }
  // The network, for cv::dnn::Net::getPerfProfile (per-layer times of the last forward).
  cv::dnn::Net& network() { return net_; }

 private:
  using Clock = std::chrono::steady_clock;
  static double elapsed_ms(Clock::time_point since) {
    return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
  }
  void make_blob(const cv::Mat& bgr);

  SegmenterMetadata meta_;
  cv::dnn::Net net_;
  cv::Mat resized_;  // buffers reused between frames
  cv::Mat blob_;
  cv::Mat logits_;
  cv::Mat labels_small_;
  StageTimes stage_times_;
};

}  // namespace pspslam
