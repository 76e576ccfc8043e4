#include "pspslam/semantic/onnx_segmenter.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "pspslam/core/error.h"

namespace pspslam {

OnnxSegmenter::OnnxSegmenter(SegmenterMetadata metadata) : meta_(std::move(metadata)) {
  try {
    net_ = cv::dnn::readNetFromONNX(meta_.onnx.string());
  } catch (const cv::Exception& e) {
    throw Error("cannot load ONNX model '" + meta_.onnx.string() + "' (from " +
                meta_.file.string() + "): " + e.what());
  }
  if (net_.empty()) throw Error("ONNX model '" + meta_.onnx.string() + "' is empty");
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  const int dims[4] = {1, 3, meta_.input_height, meta_.input_width};
  blob_.create(4, dims, CV_32F);
}

std::unique_ptr<OnnxSegmenter> OnnxSegmenter::from_file(const std::filesystem::path& file) {
  return std::make_unique<OnnxSegmenter>(load_segmenter_metadata(file));
}

std::vector<int> OnnxSegmenter::default_dynamic_classes() const {
  return class_ids(meta_.classes, meta_.dynamic_classes, meta_.file.string());
}

void OnnxSegmenter::make_blob(const cv::Mat& bgr) {
  if (bgr.empty() || bgr.type() != CV_8UC3) {
    throw Error("OnnxSegmenter: expected a non-empty CV_8UC3 BGR image");
  }
  const cv::Size size(meta_.input_width, meta_.input_height);
  const cv::Mat* src = &bgr;
  if (bgr.size() != size) {
    cv::resize(bgr, resized_, size, 0, 0, cv::INTER_LINEAR);
    src = &resized_;
  }
  // Plane k of the blob receives the k-th network channel; (p - mean) / std in float, written
  // as a division so that the numbers equal the Python export's bit for bit.
  const size_t plane = static_cast<size_t>(size.area());
  float* out[3];
  for (int k = 0; k < 3; ++k) out[k] = blob_.ptr<float>() + k * plane;
  int source_channel[3] = {0, 1, 2};
  if (meta_.rgb) std::swap(source_channel[0], source_channel[2]);
  float mean[3], stdev[3];
  for (int k = 0; k < 3; ++k) {
    mean[k] = static_cast<float>(meta_.mean[k]);
    stdev[k] = static_cast<float>(meta_.std[k]);
  }
  for (int y = 0; y < size.height; ++y) {
    const cv::Vec3b* row = src->ptr<cv::Vec3b>(y);
    const size_t base = static_cast<size_t>(y) * size.width;
    for (int x = 0; x < size.width; ++x) {
      for (int k = 0; k < 3; ++k) {
        out[k][base + x] = (static_cast<float>(row[x][source_channel[k]]) - mean[k]) / stdev[k];
      }
    }
  }
}

const cv::Mat& OnnxSegmenter::logits(const cv::Mat& bgr) {
  make_blob(bgr);
  net_.setInput(blob_);
  logits_ = net_.forward();
  const int classes = static_cast<int>(meta_.classes.size());
  const int h = meta_.input_height / meta_.output_stride;
  const int w = meta_.input_width / meta_.output_stride;
  if (logits_.dims != 4 || logits_.size[0] != 1 || logits_.size[1] != classes ||
      logits_.size[2] != h || logits_.size[3] != w) {
    std::string shape;
    for (int i = 0; i < logits_.dims; ++i) {
      if (i > 0) shape += 'x';
      shape += std::to_string(logits_.size[i]);
    }
    throw Error(meta_.file.string() + ": network output is " + shape + ", metadata says 1x" +
                std::to_string(classes) + "x" + std::to_string(h) + "x" + std::to_string(w) +
                " (classes, input / output.stride)");
  }
  return logits_;
}

LabelMap OnnxSegmenter::segment(const cv::Mat& bgr) {
  const cv::Mat& out = logits(bgr);
  const int classes = out.size[1];
  const int h = out.size[2];
  const int w = out.size[3];
  const size_t plane = static_cast<size_t>(h) * w;
  labels_small_.create(h, w, CV_8UC1);
  best_.create(h, w, CV_32FC1);
  const float* data = out.ptr<float>();
  float* best = best_.ptr<float>();
  uchar* label = labels_small_.ptr<uchar>();
  std::copy(data, data + plane, best);
  std::fill(label, label + plane, uchar{0});
  // Channel-major arg-max (first maximum wins, as numpy.argmax): streams through the logits.
  for (int c = 1; c < classes; ++c) {
    const float* v = data + c * plane;
    for (size_t i = 0; i < plane; ++i) {
      if (v[i] > best[i]) {
        best[i] = v[i];
        label[i] = static_cast<uchar>(c);
      }
    }
  }
  LabelMap labels;
  if (labels_small_.size() == bgr.size()) {
    labels = labels_small_.clone();
  } else {
    cv::resize(labels_small_, labels, bgr.size(), 0, 0, cv::INTER_NEAREST);
  }
  return labels;
}

}  // namespace pspslam
