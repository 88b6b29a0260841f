// Image masks for step 2 of Algorithm 1 (𝓜 = SAM(I), line 9), in the formats segmenters write:
//
// - A folder of binary PNGs, one per mask, 255 inside (segment-anything's
//   `amg.py --output-mode binary_mask` writes `0.png, 1.png, …` plus a metadata.csv, ignored).
// - A label PNG (8- or 16-bit): 0 outside every mask, each other value one mask.
// - COCO RLE JSON (`--output-mode coco_rle`): a list of records, or {"annotations": [...]},
//   each with "segmentation": {"size": [h, w], "counts": ...}; counts either a list of run
//   lengths (uncompressed RLE) or the compressed string of pycocotools (LEB128-like 5-bit groups
//   offset by 48, each count after the second a difference to the count two before). Runs are
//   column-major, starting with background.
//
// Masks overlap in SAM's automatic output (a part inside its whole); for the score each pixel
// belongs to the smallest mask containing it (MaskLabelImage), the most specific one.
//
// Without masks, BuiltInSegmentation stands in for SAM: k-means (k = 6) on the CIE Lab colour of
// the blurred image, then connected components of each colour cluster; components under
// `min_area` pixels are dropped. Crude next to SAM, but it needs no network and gives regions
// bounded by colour edges, which is what the consistency score compares against the cloud.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "identification/camera_lidar/camera_model.h"

namespace autoshovel::identification {

struct MaskSet {
  int width = 0, height = 0;
  std::vector<cv::Mat> masks;  ///< CV_8U, 255 inside
};

/// Reads a folder of PNGs, a label PNG or a COCO RLE .json (by what `path` is). Every mask must
/// be `width` × `height` (the image's size); throws core::InputError naming the file otherwise,
/// for an empty folder, a malformed RLE (with its line) or an unreadable PNG.
MaskSet ReadMasks(const std::string& path, int width, int height);

/// pycocotools' compressed RLE string → run lengths; throws std::invalid_argument when malformed.
std::vector<std::uint32_t> DecodeRleString(const std::string& counts);
/// Column-major runs (background first) → a height × width CV_8U mask, 255 inside; throws
/// std::invalid_argument when the runs do not add up to height·width.
cv::Mat DecodeRle(const std::vector<std::uint32_t>& runs, int height, int width);
/// The compressed string of a mask (for writing test data and `--simulate`).
std::string EncodeRleString(const cv::Mat& mask);

/// Writes `dir/0.png, 1.png, …` (creates dir).
void WriteMaskFolder(const std::string& dir, const MaskSet& masks);

/// Each mask undistorted (nearest neighbour).
MaskSet UndistortMasks(const MaskSet& masks, const CameraIntrinsics& intrinsics);

/// CV_32S: 0 outside every mask, k + 1 inside mask k (the smallest mask wins).
cv::Mat MaskLabelImage(const MaskSet& masks);

/// The built-in segmenter (see above).
MaskSet BuiltInSegmentation(const cv::Mat& bgr, int min_area = 150);

/// Connected components of each value of a label image (the simulator's per-pixel classes):
/// a SAM stand-in with perfect boundaries.
MaskSet MasksFromLabels(const cv::Mat& labels, int min_area = 150);

}  // namespace autoshovel::identification
