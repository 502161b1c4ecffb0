#include "firmware/base/status.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "firmware/base/result.h"

namespace fw {
namespace {

TEST(StatusTest, OkByDefault) {
  Status s;
  EXPECT_TRUE(s.is_ok());
  EXPECT_EQ(s.code(), Errc::kOk);
}

TEST(StatusTest, ErrorCarriesCodeAndMessageNamingTheInput) {
  Status s = Status::error(Errc::kCorruptData, "map image '%s': CRC mismatch", "intel.mmap");
  EXPECT_FALSE(s.is_ok());
  EXPECT_EQ(s.code(), Errc::kCorruptData);
  EXPECT_STREQ(s.message(), "map image 'intel.mmap': CRC mismatch");
}

TEST(StatusTest, LongMessageIsTruncatedNotOverflowed) {
  std::string longname(1000, 'x');
  Status s = Status::error(Errc::kIoError, "%s", longname.c_str());
  EXPECT_EQ(std::strlen(s.message()), Status::kMessageCapacity - 1);
  // A cut message says so.
  EXPECT_EQ(std::string(s.message()).substr(Status::kMessageCapacity - 4), "...");
}

TEST(StatusTest, RoomForALongPathAndTheProblem) {
  // Issue 13: messages were cut at 159 characters, so a long path lost the line and key.
  const std::string path(255, 'p');
  Status s = Status::error(Errc::kInvalidArgument, "config '%s' line %d: key '%s': '%s' is not an integer in 1..16",
                           path.c_str(), 12, "workers", "many");
  EXPECT_NE(std::string(s.message()).find("line 12: key 'workers': 'many' is not an integer in 1..16"),
            std::string::npos);
}

Result<int> parse_positive(int v) {
  if (v <= 0) return Status::error(Errc::kInvalidArgument, "value %d must be positive", v);
  return v * 2;
}

TEST(ResultTest, ValueOrStatus) {
  auto good = parse_positive(3);
  ASSERT_TRUE(good.has_value());
  EXPECT_EQ(*good, 6);
  auto bad = parse_positive(-1);
  ASSERT_FALSE(bad.has_value());
  EXPECT_EQ(bad.status().code(), Errc::kInvalidArgument);
  EXPECT_STREQ(bad.status().message(), "value -1 must be positive");
}

Status chain(int v) {
  FW_RETURN_IF_ERROR(parse_positive(v).status().is_ok() ? Status::ok() : parse_positive(v).status());
  return Status::ok();
}

TEST(StatusTest, ReturnIfErrorPropagates) {
  EXPECT_TRUE(chain(1).is_ok());
  EXPECT_EQ(chain(0).code(), Errc::kInvalidArgument);
}

}  // namespace
}  // namespace fw
