// Per-pixel semantic segmentation of camera frames (wheel-loader seed §4.2): the probabilities of
// the seven core::SemanticClass classes for every pixel, from an ONNX network run by OpenCV's dnn
// module on the CPU. The shipped network is models/segmentation/yard_segmenter.onnx (its
// README gives the training and the measured accuracy).
//
// Network contract (what train.py exports): input 1×3×H×W float, the frame's B, G, R bytes
// mapped to (value − 127.5) / 127.5, H and W multiples of 16; output 1×7×H×W class scores
// (logits). The network is fully convolutional, so it runs at any such size; a frame whose sides
// are not multiples of 16 (the 480×383 camera) is padded at its right and bottom by repeating
// its last column and row, and the result is cropped back. Probabilities are the softmax of the
// scores.
//
// Threads: OpenCV runs the network on its process-wide thread pool. SetInferenceThreads(1) makes
// inference single-threaded (the latency figures are measured so, leaving the other cores to
// the rest of the pipeline); a Segmenter never changes the setting itself.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/core/semantic_class.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::perception {

struct SegmentationResult {
  int width = 0, height = 0;
  /// core::kNumSemanticClasses planes of width × height, row-major, plane c the probability of
  /// class c; at every pixel the planes sum to 1.
  std::vector<float> probabilities;
  /// The most probable class of every pixel (core::SemanticClass values), row-major.
  std::vector<std::uint8_t> labels;

  float probability(core::SemanticClass c, int u, int v) const {
    return probabilities[(static_cast<std::size_t>(c) * height + v) * width + u];
  }
  core::SemanticClass label(int u, int v) const {
    return static_cast<core::SemanticClass>(labels[static_cast<std::size_t>(v) * width + u]);
  }
};

class Segmenter {
 public:
  /// Loads the network and checks it on a 480×384 input. Throws std::runtime_error naming the
  /// file when it is missing, unreadable, not an ONNX network OpenCV can run, or gives other
  /// than 7 class planes at the input's size.
  explicit Segmenter(const std::string& onnx_path);
  ~Segmenter();
  Segmenter(Segmenter&&) noexcept;
  Segmenter& operator=(Segmenter&&) noexcept;

  /// Segments one frame (its `bgr` bytes; `labels` is ignored). Throws std::invalid_argument for
  /// a frame without pixels or whose bgr buffer does not hold width × height × 3 bytes. Calls
  /// from several threads are serialised (one network instance).
  SegmentationResult Run(const sensors::CameraFrame& frame) const;
  /// The same at `scale` of the frame's resolution (0 < scale ≤ 1; issue 45): the image is
  /// shrunk (area averaging, sides at least 16 px), segmented, and the class probabilities
  /// are brought back to the frame's size by bilinear interpolation (which keeps them summing
  /// to 1); labels are their argmax. Inference costs about scale² of the full frame's.
  /// Throws std::invalid_argument for a scale outside (0, 1].
  SegmentationResult Run(const sensors::CameraFrame& frame, double scale) const;

  const std::string& model_path() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// OpenCV's process-wide thread count for inference (and every other OpenCV call).
void SetInferenceThreads(int threads);

}  // namespace autoshovel::perception
