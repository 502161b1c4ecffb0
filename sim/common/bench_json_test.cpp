// BenchJson writes valid JSON whatever a string holds (paths, error messages).
#include "sim/common/bench_json.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace sim {
namespace {

TEST(BenchJsonTest, StringsAreEscaped) {
  EXPECT_EQ(BenchJson::quoted("plain"), "\"plain\"");
  EXPECT_EQ(BenchJson::quoted("a\"b"), "\"a\\\"b\"");
  EXPECT_EQ(BenchJson::quoted("C:\\maps"), "\"C:\\\\maps\"");
  EXPECT_EQ(BenchJson::quoted("line1\nline2\tx"), "\"line1\\nline2\\tx\"");
  EXPECT_EQ(BenchJson::quoted(std::string("\x01", 1)), "\"\\u0001\"");
}

TEST(BenchJsonTest, WrittenFileHoldsTheEscapedValues) {
  BenchJson j;
  j.add("figure", 1.5);
  j.add_string("note", "log \"x\" at /tmp\\y\n");
  const std::string path = ::testing::TempDir() + "bench_json_test.json";
  ASSERT_TRUE(j.write(path));
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "{\n  \"figure\": 1.5,\n  \"note\": \"log \\\"x\\\" at /tmp\\\\y\\n\"\n}\n");
  std::remove(path.c_str());
}

}  // namespace
}  // namespace sim
