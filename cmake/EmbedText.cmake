# Writes a C++ source defining `std::string_view NAMESPACE::FUNCTION()` that returns the bytes of
# INPUT, so that a binary carries a header's text (runtime/machines/CMakeLists.txt: the headers a
# machine library is compiled against, away from the source tree). Run with cmake -P:
#   -DINPUT=file -DOUTPUT=file.cc -DNAMESPACE=a::b -DFUNCTION=Name
file(READ "${INPUT}" text)
set(delimiter "autoshovel_embed")
string(FIND "${text}" ")${delimiter}\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter )${delimiter}\"")
endif()
file(WRITE "${OUTPUT}.tmp"
  "// Generated at build time from ${INPUT} by cmake/EmbedText.cmake -- do not edit.\n"
  "#include <string_view>\n\n"
  "namespace ${NAMESPACE} {\n\n"
  "std::string_view ${FUNCTION}() {\n"
  "  static constexpr char kText[] = R\"${delimiter}(${text})${delimiter}\";\n"
  "  return {kText, sizeof(kText) - 1};\n"
  "}\n\n"
  "}  // namespace ${NAMESPACE}\n")
file(COPY_FILE "${OUTPUT}.tmp" "${OUTPUT}" ONLY_IF_DIFFERENT)
file(REMOVE "${OUTPUT}.tmp")
