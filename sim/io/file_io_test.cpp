// Hostile paths for the host tools' file helpers (issue 13): a FIFO, /dev/zero and a directory are
// refused by stat before anything is opened or read (no block, no endless read, no exception), the
// size cap holds before allocation, and outputs are replaced only by complete files.
#include "sim/io/file_io.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "sim/common/cli_main.h"

namespace sim {
namespace {

namespace fs = std::filesystem;

class FileIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("file_io_test_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write_text(const std::string& name, const std::string& text) const {
    std::ofstream o(path(name), std::ios::binary);
    o << text;
  }
  // Files in the test directory other than `keep` (temporaries left behind would show here).
  std::vector<std::string> others(const std::string& keep) const {
    std::vector<std::string> v;
    for (const auto& e : fs::directory_iterator(dir_)) {
      if (e.path().filename() != keep) v.push_back(e.path().filename().string());
    }
    return v;
  }
  fs::path dir_;
};

TEST_F(FileIoTest, FifoDeviceAndDirectoryAreRefusedWithoutBlocking) {
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
  std::string data, err;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(read_regular_file(path("fifo"), 1 << 20, &data, &err));  // would block in open() without a writer
  EXPECT_NE(err.find(path("fifo") + ": not a regular file (a FIFO)"), std::string::npos) << err;
  EXPECT_FALSE(read_regular_file("/dev/zero", 1 << 20, &data, &err));  // would never end
  EXPECT_NE(err.find("/dev/zero: not a regular file (a character device)"), std::string::npos) << err;
  std::vector<std::uint8_t> bytes;
  EXPECT_FALSE(read_regular_file(dir_.string(), 1 << 20, &bytes, &err));  // ifstream threw on this
  EXPECT_NE(err.find("not a regular file (a directory)"), std::string::npos) << err;
  EXPECT_FALSE(read_regular_file(path("missing"), 1 << 20, &data, &err));
  EXPECT_NE(err.find(path("missing") + ": cannot open: No such file"), std::string::npos) << err;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
  EXPECT_TRUE(data.empty());
}

TEST_F(FileIoTest, SizeCapIsCheckedBeforeReading) {
  write_text("big", std::string(5000, 'x'));
  std::string data, err;
  EXPECT_FALSE(read_regular_file(path("big"), 4999, &data, &err));
  EXPECT_NE(err.find("5000 bytes, more than the limit of 4999 bytes"), std::string::npos) << err;
  EXPECT_TRUE(data.empty());
  ASSERT_TRUE(read_regular_file(path("big"), 5000, &data, &err)) << err;
  EXPECT_EQ(data, std::string(5000, 'x'));
  std::uint64_t size = 0;
  ASSERT_TRUE(check_regular_file(path("big"), 5000, &size, &err)) << err;
  EXPECT_EQ(size, 5000u);
  write_text("empty", "");
  ASSERT_TRUE(read_regular_file(path("empty"), 10, &data, &err)) << err;
  EXPECT_TRUE(data.empty());
}

TEST_F(FileIoTest, AtomicWriteReplacesOnlyWithACompleteFile) {
  std::string err;
  ASSERT_TRUE(write_file_atomic(path("out"), std::string("first"), &err)) << err;
  ASSERT_TRUE(write_file_atomic(path("out"), std::string("second"), &err)) << err;
  std::string data;
  ASSERT_TRUE(read_regular_file(path("out"), 100, &data, &err)) << err;
  EXPECT_EQ(data, "second");
  EXPECT_TRUE(others("out").empty());  // no temporaries left
  struct stat st {};
  ASSERT_EQ(::stat(path("out").c_str(), &st), 0);
  const mode_t mask = ::umask(0);
  ::umask(mask);
  EXPECT_EQ(st.st_mode & 0777, 0666u & ~mask) << "outputs get the usual permissions, not mkstemp's 0600";
  // Failures name the path and leave nothing behind.
  EXPECT_FALSE(write_file_atomic(path("no/such/dir/out"), std::string("x"), &err));
  EXPECT_NE(err.find(path("no/such/dir/out")), std::string::npos) << err;
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
  EXPECT_FALSE(write_file_atomic(path("fifo"), std::string("x"), &err));
  EXPECT_NE(err.find("not a regular file (a FIFO)"), std::string::npos) << err;
  fs::create_directory(path("adir"));
  EXPECT_FALSE(write_file_atomic(path("adir"), std::string("x"), &err));
  EXPECT_NE(err.find("a directory"), std::string::npos) << err;
  EXPECT_EQ(others("out").size(), 2u);  // fifo and adir, no temporaries
}

TEST(CliMain, EscapedExceptionsBecomeAMessageAndStatus1) {
  testing::internal::CaptureStderr();
  const int a = guarded_main("tool-a", [] () -> int { throw std::runtime_error("boom in body"); });
  const int b = guarded_main("tool-b", [] () -> int { throw 42; });
  const int c = guarded_main("tool-c", [] { return 7; });
  const std::string out = testing::internal::GetCapturedStderr();
  EXPECT_EQ(a, 1);
  EXPECT_EQ(b, 1);
  EXPECT_EQ(c, 7);
  EXPECT_NE(out.find("tool-a: boom in body"), std::string::npos) << out;
  EXPECT_NE(out.find("tool-b: unknown exception"), std::string::npos) << out;
  std::set_terminate(nullptr);
}

}  // namespace
}  // namespace sim
