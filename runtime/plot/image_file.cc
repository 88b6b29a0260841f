#include "runtime/plot/image_file.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "runtime/core/file_output.h"

namespace autoshovel::plot {

void WriteImageFile(const std::filesystem::path& path, const cv::Mat& image) {
  if (image.empty()) throw core::OutputError(path, "the image is empty");
  std::string extension = path.extension().string();
  if (extension.empty()) extension = ".png";
  std::vector<unsigned char> bytes;
  try {
    if (!cv::imencode(extension, image, bytes)) {
      throw core::OutputError(path, "OpenCV cannot encode a " + extension + " image");
    }
  } catch (const cv::Exception& e) {
    throw core::OutputError(path, "OpenCV cannot encode it: " + e.msg);
  }
  core::WriteFileAtomically(
      path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace autoshovel::plot
