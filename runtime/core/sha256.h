// SHA-256 of files, for the banners of generated code and the run configuration record.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace autoshovel::core {

/// Lower-case hex SHA-256 of `bytes` (OpenSSL's EVP interface: a well-kept implementation
/// rather than one of our own).
std::string Sha256Hex(std::string_view bytes);

/// Reads a whole file as bytes. Throws std::runtime_error naming the path if it cannot.
std::string ReadFileBytes(const std::filesystem::path& path);

}  // namespace autoshovel::core
