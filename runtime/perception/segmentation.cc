#include "runtime/perception/segmentation.h"

#include <filesystem>
#include <fstream>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace autoshovel::perception {
namespace {

constexpr int kClasses = core::kNumSemanticClasses;
// The network halves the resolution four times: sides must be multiples of 16.
constexpr int kStride = 16;
// The size the network is checked at when loaded: the 480×383 camera padded to 384 rows.
constexpr int kProbeWidth = 480, kProbeHeight = 384;

int RoundUp(int v) { return (v + kStride - 1) / kStride * kStride; }

std::string ShapeText(const cv::Mat& m) {
  std::string s;
  for (int d = 0; d < m.dims; ++d) s += (d ? "x" : "") + std::to_string(m.size[d]);
  return s.empty() ? "nothing" : s;
}

}  // namespace

struct Segmenter::Impl {
  std::string path;
  std::mutex mutex;  // cv::dnn::Net::forward is neither const nor thread-safe
  cv::dnn::Net net;

  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error("segmentation model " + path + ": " + what);
  }

  // Returns the network's output for a 1×3×H×W blob; the Mat is valid until the next call.
  cv::Mat Forward(const cv::Mat& blob) {
    net.setInput(blob);
    return net.forward();
  }
};

Segmenter::Segmenter(const std::string& onnx_path) : impl_(std::make_unique<Impl>()) {
  impl_->path = onnx_path;
  std::error_code error;
  if (!std::filesystem::is_regular_file(onnx_path, error)) impl_->Fail("no such file");
  if (!std::ifstream(onnx_path, std::ios::binary)) impl_->Fail("cannot be read");
  try {
    impl_->net = cv::dnn::readNetFromONNX(onnx_path);
  } catch (const cv::Exception& e) {
    impl_->Fail("not an ONNX network OpenCV can load (" + e.err + ")");
  }
  if (impl_->net.empty()) impl_->Fail("not an ONNX network OpenCV can load (empty network)");
  impl_->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  impl_->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);

  // Run it once: a wrong input or output layout shows here rather than on the first frame.
  const int probe_shape[] = {1, 3, kProbeHeight, kProbeWidth};
  const cv::Mat probe(4, probe_shape, CV_32F, cv::Scalar(0));
  cv::Mat out;
  try {
    out = impl_->Forward(probe);
  } catch (const cv::Exception& e) {
    impl_->Fail("cannot run on a 1x3x" + std::to_string(kProbeHeight) + "x" +
                std::to_string(kProbeWidth) + " BGR input (" + e.err + ")");
  }
  if (out.dims != 4 || out.size[0] != 1 || out.size[1] != kClasses || out.size[2] != kProbeHeight ||
      out.size[3] != kProbeWidth || out.type() != CV_32F) {
    impl_->Fail("gives " + ShapeText(out) + " for a 1x3x" + std::to_string(kProbeHeight) + "x" +
                std::to_string(kProbeWidth) + " input, expected 1x" + std::to_string(kClasses) +
                "x" + std::to_string(kProbeHeight) + "x" + std::to_string(kProbeWidth) +
                " float class scores (one plane per core::SemanticClass at the input's size)");
  }
}

Segmenter::~Segmenter() = default;
Segmenter::Segmenter(Segmenter&&) noexcept = default;
Segmenter& Segmenter::operator=(Segmenter&&) noexcept = default;

const std::string& Segmenter::model_path() const { return impl_->path; }

SegmentationResult Segmenter::Run(const sensors::CameraFrame& frame) const {
  const int w = frame.width, h = frame.height;
  if (w <= 0 || h <= 0 || frame.bgr.empty()) {
    throw std::invalid_argument("Segmenter::Run: the frame has no pixels (" + std::to_string(w) +
                                "x" + std::to_string(h) + ", " + std::to_string(frame.bgr.size()) +
                                " bgr bytes)");
  }
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  if (frame.bgr.size() != 3 * n) {
    throw std::invalid_argument("Segmenter::Run: a " + std::to_string(w) + "x" + std::to_string(h) +
                                " frame needs " + std::to_string(3 * n) + " bgr bytes, got " +
                                std::to_string(frame.bgr.size()));
  }
  const cv::Mat image(h, w, CV_8UC3, const_cast<std::uint8_t*>(frame.bgr.data()));
  cv::Mat padded;
  cv::copyMakeBorder(image, padded, 0, RoundUp(h) - h, 0, RoundUp(w) - w, cv::BORDER_REPLICATE);
  // (value − 127.5) / 127.5 per channel, BGR order kept (the network is trained on BGR).
  const cv::Mat blob = cv::dnn::blobFromImage(padded, 1.0 / 127.5, cv::Size(),
                                              cv::Scalar(127.5, 127.5, 127.5), false, false);

  SegmentationResult result;
  result.width = w;
  result.height = h;
  result.probabilities.resize(kClasses * n);
  result.labels.resize(n);

  const std::lock_guard<std::mutex> lock(impl_->mutex);
  const cv::Mat out = impl_->Forward(blob);
  if (out.dims != 4 || out.size[1] != kClasses || out.size[2] != padded.rows ||
      out.size[3] != padded.cols) {
    impl_->Fail("gives " + ShapeText(out) + " for a " + std::to_string(padded.cols) + "x" +
                std::to_string(padded.rows) + " input");
  }
  // Class planes cropped to the frame, and the result's planes, as Mats over their memory.
  std::vector<cv::Mat> scores(kClasses), probs(kClasses);
  for (int c = 0; c < kClasses; ++c) {
    scores[c] = cv::Mat(padded.rows, padded.cols, CV_32F,
                        const_cast<float*>(out.ptr<float>(0, c)))(cv::Rect(0, 0, w, h));
    probs[c] = cv::Mat(h, w, CV_32F, result.probabilities.data() + c * n);
  }
  // Softmax, shifted by the per-pixel maximum so that exp never overflows.
  cv::Mat max_score = scores[0].clone();
  for (int c = 1; c < kClasses; ++c) cv::max(max_score, scores[c], max_score);
  cv::Mat sum(h, w, CV_32F, cv::Scalar(0));
  for (int c = 0; c < kClasses; ++c) {
    cv::subtract(scores[c], max_score, probs[c]);
    cv::exp(probs[c], probs[c]);
    sum += probs[c];
  }
  for (int c = 0; c < kClasses; ++c) cv::divide(probs[c], sum, probs[c]);
  // Argmax of the scores (the same as of the probabilities, without rounding ties).
  for (int v = 0; v < h; ++v) {
    const float* row[kClasses];
    for (int c = 0; c < kClasses; ++c) row[c] = scores[c].ptr<float>(v);
    std::uint8_t* label = result.labels.data() + static_cast<std::size_t>(v) * w;
    for (int u = 0; u < w; ++u) {
      int best = 0;
      for (int c = 1; c < kClasses; ++c) {
        if (row[c][u] > row[best][u]) best = c;
      }
      label[u] = static_cast<std::uint8_t>(best);
    }
  }
  return result;
}

SegmentationResult Segmenter::Run(const sensors::CameraFrame& frame, double scale) const {
  if (!(scale > 0 && scale <= 1)) {
    throw std::invalid_argument("Segmenter::Run: scale must be in (0, 1], got " +
                                std::to_string(scale));
  }
  if (scale == 1) return Run(frame);
  const int w = frame.width, h = frame.height;
  if (w <= 0 || h <= 0 || frame.bgr.size() != 3 * static_cast<std::size_t>(w) * h) {
    return Run(frame);  // refuses it with the full-size message
  }
  const cv::Mat image(h, w, CV_8UC3, const_cast<std::uint8_t*>(frame.bgr.data()));
  sensors::CameraFrame small;
  small.stamp = frame.stamp;
  small.width = std::max(16, static_cast<int>(std::lround(w * scale)));
  small.height = std::max(16, static_cast<int>(std::lround(h * scale)));
  cv::Mat shrunk;
  cv::resize(image, shrunk, cv::Size(small.width, small.height), 0, 0, cv::INTER_AREA);
  small.bgr.assign(shrunk.data, shrunk.data + shrunk.total() * 3);
  const SegmentationResult coarse = Run(small);
  SegmentationResult result;
  result.width = w;
  result.height = h;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  const std::size_t coarse_n = static_cast<std::size_t>(coarse.width) * coarse.height;
  result.probabilities.resize(kClasses * n);
  for (int c = 0; c < kClasses; ++c) {
    const cv::Mat plane(coarse.height, coarse.width, CV_32F,
                        const_cast<float*>(coarse.probabilities.data() + c * coarse_n));
    cv::Mat full(h, w, CV_32F, result.probabilities.data() + c * n);
    cv::resize(plane, full, full.size(), 0, 0, cv::INTER_LINEAR);
  }
  result.labels.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    int best = 0;
    for (int c = 1; c < kClasses; ++c) {
      if (result.probabilities[c * n + i] > result.probabilities[best * n + i]) best = c;
    }
    result.labels[i] = static_cast<std::uint8_t>(best);
  }
  return result;
}

void SetInferenceThreads(int threads) { cv::setNumThreads(threads); }

}  // namespace autoshovel::perception
