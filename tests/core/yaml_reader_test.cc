#include "runtime/core/yaml_reader.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace autoshovel::core {
namespace {

std::filesystem::path WriteTemp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path;
}

TEST(NumberRule, MessagesNameTheBoundTheUnitAndTheValue) {
  EXPECT_EQ(NumberRule::Positive("m").Check(1.0), "");
  EXPECT_EQ(NumberRule::Positive("m").Check(-1.3), "must be > 0 m, got -1.3 m");
  EXPECT_EQ(NumberRule::NonNegative("kg").Check(0.0), "");
  EXPECT_EQ(NumberRule::Closed(-180, 180, "deg").Check(200),
            "must be in [-180, 180] deg, got 200 deg");
  EXPECT_EQ(NumberRule::Open(0, 1, "").Check(1), "must be in (0, 1), got 1");
}

TEST(MapReader, ReportsMissingWrongAndUnknownKeysWithLocations) {
  const auto path = WriteTemp("autoshovel_reader_test.yaml",
                              "a: 1.5\n"
                              "b: text\n"
                              "lenght: 2\n"
                              "nested:\n"
                              "  c: -1\n");
  DiagnosticSink sink;
  const YamlFile file(path, sink);
  MapReader root = MapReader::Root(file, nullptr);
  EXPECT_DOUBLE_EQ(root.Number("a", NumberRule::Positive("m")), 1.5);
  root.Number("b", NumberRule::Any());
  root.Number("length", NumberRule::Positive("m"));
  MapReader nested = root.Map("nested");
  nested.Number("c", NumberRule::Positive("m"));
  nested.Finish();
  root.Finish();
  const auto& d = sink.diagnostics();
  // The misspelt 'lenght' explains the missing 'length': one line, not two.
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(d[0].ToString(), path.string() + ":2:4: b: expected a number, got 'text'");
  EXPECT_EQ(d[1].ToString(), path.string() + ":5:6: nested.c: must be > 0 m, got -1 m");
  EXPECT_EQ(d[2].ToString(),
            path.string() + ":3:1: lenght: unknown key 'lenght' (did you mean 'length'?)");
}

TEST(MapReader, ReportsAMissingKeyAtItsMapping) {
  const auto path = WriteTemp("autoshovel_reader_missing.yaml", "a: 1\nnested:\n  b: 2\n");
  DiagnosticSink sink;
  const YamlFile file(path, sink);
  MapReader root = MapReader::Root(file, nullptr);
  root.Number("a", NumberRule::Any());
  MapReader nested = root.Map("nested");
  nested.Number("b", NumberRule::Any());
  nested.Number("c", NumberRule::Any());
  nested.Finish();
  root.Finish();
  ASSERT_EQ(sink.diagnostics().size(), 1u);
  EXPECT_EQ(sink.diagnostics()[0].ToString(),
            path.string() + ":3:3: nested: missing required key 'c'");
}

TEST(MapReader, RefusesNonFiniteNumbers) {
  const auto path = WriteTemp("autoshovel_reader_nan.yaml", "a: .nan\nb: .inf\n");
  DiagnosticSink sink;
  const YamlFile file(path, sink);
  MapReader root = MapReader::Root(file, nullptr);
  root.Number("a", NumberRule::Any());
  root.Number("b", NumberRule::Any());
  ASSERT_EQ(sink.diagnostics().size(), 2u);
  EXPECT_EQ(sink.diagnostics()[0].message, "expected a finite number, got '.nan'");
}

TEST(YamlFile, SyntaxErrorsCarryTheirLocation) {
  const auto path = WriteTemp("autoshovel_reader_syntax.yaml", "a: [1, 2\nb: 3\n");
  DiagnosticSink sink;
  const YamlFile file(path, sink);
  EXPECT_FALSE(file.ok());
  ASSERT_EQ(sink.diagnostics().size(), 1u);
  EXPECT_GT(sink.diagnostics()[0].where.line, 0);
  EXPECT_NE(sink.diagnostics()[0].message.find("YAML syntax error"), std::string::npos);
}

// Issue 38, defect 4: yaml-cpp keeps both pairs of a repeated key and `node[key]` returns the
// first, so a correction appended to a file was silently ignored.
TEST(YamlFile, RefusesADuplicateKeyWithBothLocations) {
  const auto path = WriteTemp("autoshovel_reader_duplicate.yaml",
                              "name: arm\n"
                              "length: 3.11\n"
                              "mass: 10\n"
                              "length: 5.0\n");
  DiagnosticSink sink;
  const YamlFile file(path, sink);
  EXPECT_FALSE(file.ok());
  ASSERT_EQ(sink.diagnostics().size(), 1u);
  EXPECT_EQ(sink.diagnostics()[0].ToString(),
            path.string() + ":4:1: length: duplicate key 'length' (first at line 2)");
}

TEST(YamlFile, NamesTheFullKeyPathOfANestedDuplicate) {
  const auto path = WriteTemp("autoshovel_reader_duplicate_nested.yaml",
                              "arm:\n"
                              "  links:\n"
                              "    - name: boom\n"
                              "      length: 3.11\n"
                              "    - name: stick\n"
                              "      length: 2.0\n"
                              "      length: 2.5\n"
                              "flow: {a: 1, b: 2, a: 3}\n");
  DiagnosticSink sink;
  const YamlFile file(path, sink);
  EXPECT_FALSE(file.ok());
  ASSERT_EQ(sink.diagnostics().size(), 2u);
  EXPECT_EQ(sink.diagnostics()[0].ToString(),
            path.string() + ":7:7: arm.links[1].length: duplicate key 'length' (first at line 6)");
  EXPECT_EQ(sink.diagnostics()[1].ToString(),
            path.string() + ":8:20: flow.a: duplicate key 'a' (first at line 8)");
}

TEST(YamlFile, AcceptsTheSameKeyInDifferentMappingsAndAliases) {
  const auto path = WriteTemp("autoshovel_reader_same_key.yaml",
                              "a: {length: 1}\n"
                              "b: {length: 2}\n"
                              "list: [{length: 3}, {length: 4}]\n"
                              "base: &base {length: 5}\n"
                              "copy: *base\n");
  DiagnosticSink sink;
  const YamlFile file(path, sink);
  EXPECT_TRUE(file.ok());
  EXPECT_TRUE(sink.empty());
}

// Issue 38, defect 6: a 70 MB YAML took 3.2 GB and 24 s before its first error. The size is
// checked before any byte is parsed; the file here is mostly one comment, which would parse.
TEST(YamlFile, RefusesAFileOverTheSizeLimitBeforeParsing) {
  const auto path = std::filesystem::temp_directory_path() / "autoshovel_reader_huge.yaml";
  {
    std::ofstream out(path, std::ios::binary);
    out << "a: 1\n# ";
    const std::string line(1023, 'x');
    for (std::uintmax_t written = 0; written <= kMaxYamlBytes; written += 1024) {
      out << line << '\n';
    }
  }
  const auto bytes = std::filesystem::file_size(path);
  ASSERT_GT(bytes, kMaxYamlBytes);
  DiagnosticSink sink;
  const YamlFile file(path, sink);
  EXPECT_FALSE(file.ok());
  ASSERT_EQ(sink.diagnostics().size(), 1u);
  EXPECT_EQ(sink.diagnostics()[0].ToString().rfind(
                path.string() + ": the file is " + std::to_string(bytes) +
                    " bytes (16.0 MiB), "
                    "more than the 16.0 MiB a YAML input may have",
                0),
            0u)
      << sink.diagnostics()[0].ToString();
  std::filesystem::remove(path);
}

TEST(LoadYamlFile, TakesItsLimitAndReadsNonMappingRoots) {
  const auto path = WriteTemp("autoshovel_reader_list.json", "[{\"a\": 1}, {\"a\": 2}]\n");
  DiagnosticSink sink;
  EXPECT_EQ(LoadYamlFile(path, sink).size(), 2u);
  EXPECT_TRUE(sink.empty());
  EXPECT_TRUE(LoadYamlFile(path, sink, /*max_bytes=*/8).IsNull());
  ASSERT_EQ(sink.diagnostics().size(), 1u);
  EXPECT_EQ(sink.diagnostics()[0].where.line, 0);
}

}  // namespace
}  // namespace autoshovel::core
