// Writing a picture (PNG, JPEG, by the path's extension) with the same guarantees as every other
// file the project writes (runtime/core/file_output.h): encoded in memory, then written to a
// temporary file, fsync'ed and renamed, each step checked. cv::imwrite reports failure as a bare
// `false` and writes in place, so a full disk could leave half a PNG under the final name.
#pragma once

#include <filesystem>

namespace cv {
class Mat;
}

namespace autoshovel::plot {

/// Encodes `image` by `path`'s extension and writes it atomically. Throws core::OutputError
/// (path and reason) when the image cannot be encoded or written; the old file is then untouched.
void WriteImageFile(const std::filesystem::path& path, const cv::Mat& image);

}  // namespace autoshovel::plot
