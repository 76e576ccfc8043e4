#include "pspslam/semantic/onnx_segmenter.h"

#include <opencv2/core/hal/intrin.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "pspslam/core/error.h"

namespace pspslam {
namespace {

// Writes (pixel - mean) / std of the image's channel source_channel[k] into plane k, 16 pixels
// at a time (OpenCV universal intrinsics: the runtime channel order keeps the compiler from
// vectorising the plain loop). Float subtraction and division as in the Python export, so the
// blob is bit-identical to it.
void normalise_into_planes(const cv::Mat& bgr, const int source_channel[3], const float mean[3],
                           const float stdev[3], float* const planes[3]) {
  const int width = bgr.cols;
  cv::v_float32x4 mean_vec[3], std_vec[3];
  for (int k = 0; k < 3; ++k) {
    mean_vec[k] = cv::v_setall_f32(mean[k]);
    std_vec[k] = cv::v_setall_f32(stdev[k]);
  }
  for (int y = 0; y < bgr.rows; ++y) {
    const uchar* row = bgr.ptr<uchar>(y);
    const size_t offset = static_cast<size_t>(y) * width;
    int x = 0;
    for (; x + 16 <= width; x += 16) {
      cv::v_uint8x16 channel[3];
      cv::v_load_deinterleave(row + 3 * x, channel[0], channel[1], channel[2]);
      for (int k = 0; k < 3; ++k) {
        cv::v_uint16x8 words[2];
        cv::v_uint32x4 ints[4];
        cv::v_expand(channel[source_channel[k]], words[0], words[1]);
        cv::v_expand(words[0], ints[0], ints[1]);
        cv::v_expand(words[1], ints[2], ints[3]);
        for (int j = 0; j < 4; ++j) {
          const cv::v_float32x4 value = cv::v_cvt_f32(cv::v_reinterpret_as_s32(ints[j]));
          cv::v_store(planes[k] + offset + x + 4 * j, (value - mean_vec[k]) / std_vec[k]);
        }
      }
    }
    for (; x < width; ++x) {
      for (int k = 0; k < 3; ++k) {
        const float value = static_cast<float>(row[3 * x + source_channel[k]]);
        planes[k][offset + x] = (value - mean[k]) / stdev[k];
      }
    }
  }
}

// Arg-max over `classes` planes of `plane` logits each (first maximum wins, as numpy.argmax).
// One pass over the logits: 16 pixels keep their best value and class in registers while the
// class planes stream by (the class id is carried as a float so that compare and select stay
// in one lane width): comparing plane by plane against a best-value buffer in memory costs most
// of the post-processing.
void argmax_over_planes(const float* logits, int classes, size_t plane, uchar* labels) {
  size_t i = 0;
  for (; i + 16 <= plane; i += 16) {
    cv::v_float32x4 best[4], best_class[4];
    for (int k = 0; k < 4; ++k) {
      best[k] = cv::v_load(logits + i + 4 * k);
      best_class[k] = cv::v_setzero_f32();
    }
    for (int c = 1; c < classes; ++c) {
      const float* values = logits + c * plane + i;
      const cv::v_float32x4 id = cv::v_setall_f32(static_cast<float>(c));
      for (int k = 0; k < 4; ++k) {
        const cv::v_float32x4 value = cv::v_load(values + 4 * k);
        const cv::v_float32x4 greater = value > best[k];
        best[k] = cv::v_select(greater, value, best[k]);
        best_class[k] = cv::v_select(greater, id, best_class[k]);
      }
    }
    const cv::v_int16x8 low = cv::v_pack(cv::v_round(best_class[0]), cv::v_round(best_class[1]));
    const cv::v_int16x8 high = cv::v_pack(cv::v_round(best_class[2]), cv::v_round(best_class[3]));
    cv::v_store(labels + i, cv::v_pack_u(low, high));
  }
  for (; i < plane; ++i) {
    float best = logits[i];
    uchar label = 0;
    for (int c = 1; c < classes; ++c) {
      const float value = logits[c * plane + i];
      if (value > best) {
        best = value;
        label = static_cast<uchar>(c);
      }
    }
    labels[i] = label;
  }
}

}  // namespace

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
  const size_t plane = static_cast<size_t>(size.area());
  float* const planes[3] = {blob_.ptr<float>(), blob_.ptr<float>() + plane,
                            blob_.ptr<float>() + 2 * plane};
  int source_channel[3] = {0, 1, 2};
  if (meta_.rgb) std::swap(source_channel[0], source_channel[2]);
  float mean[3], stdev[3];
  for (int k = 0; k < 3; ++k) {
    mean[k] = static_cast<float>(meta_.mean[k]);
    stdev[k] = static_cast<float>(meta_.std[k]);
  }
  normalise_into_planes(*src, source_channel, mean, stdev, planes);
}

const cv::Mat& OnnxSegmenter::logits(const cv::Mat& bgr) {
  const Clock::time_point start = Clock::now();
  make_blob(bgr);
  stage_times_.preprocess_ms = elapsed_ms(start);
  const Clock::time_point network_start = Clock::now();
  net_.setInput(blob_);
  logits_ = net_.forward();
  stage_times_.network_ms = elapsed_ms(network_start);
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
  const Clock::time_point start = Clock::now();
  const int classes = out.size[1];
  const int h = out.size[2];
  const int w = out.size[3];
  labels_small_.create(h, w, CV_8UC1);
  argmax_over_planes(out.ptr<float>(), classes, static_cast<size_t>(h) * w,
                     labels_small_.ptr<uchar>());
  LabelMap labels;
  if (labels_small_.size() == bgr.size()) {
    labels = labels_small_.clone();
  } else {
    cv::resize(labels_small_, labels, bgr.size(), 0, 0, cv::INTER_NEAREST);
  }
  stage_times_.postprocess_ms = elapsed_ms(start);
  return labels;
}

}  // namespace pspslam
