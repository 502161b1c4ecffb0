// SdNotify against a real AF_UNIX datagram socket: the test binds the receiver (as systemd does
// for NOTIFY_SOCKET), the sender under test sends, and the datagrams are read back.
#include "hal_linux/sd_notify.h"

#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <string>

namespace hal_linux {
namespace {

// Receiver bound to a path (or an abstract name when it starts with '@').
struct Receiver {
  int fd = -1;
  std::string name;
  bool bind_to(const std::string& n) {
    name = n;
    fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return false;
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::memcpy(a.sun_path, n.data(), n.size());
    if (n[0] == '@') a.sun_path[0] = '\0';
    else ::unlink(n.c_str());
    return ::bind(fd, reinterpret_cast<sockaddr*>(&a), static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + n.size())) == 0;
  }
  // Next datagram, "" after timeout_ms without one.
  std::string next(int timeout_ms = 1000) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, timeout_ms) != 1) return "";
    char buf[512];
    const ssize_t n = ::recv(fd, buf, sizeof(buf), 0);
    return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
  }
  ~Receiver() {
    if (fd >= 0) ::close(fd);
    if (!name.empty() && name[0] == '/') ::unlink(name.c_str());
  }
};

std::string temp_socket_path(const char* tag) {
  return "/tmp/mmlfw_sd_notify_" + std::string(tag) + "_" + std::to_string(::getpid());
}

TEST(SdNotify, SendsDatagramsToAPathSocket) {
  Receiver r;
  ASSERT_TRUE(r.bind_to(temp_socket_path("path")));
  SdNotify n;
  ASSERT_TRUE(n.open(r.name.c_str(), "2000000", nullptr, 42).is_ok());
  EXPECT_TRUE(n.enabled());
  EXPECT_EQ(n.watchdog_period_ns(), 2000000000ull);
  ASSERT_TRUE(n.send("READY=1").is_ok());
  ASSERT_TRUE(n.send("STATUS=searching, 0 scans").is_ok());
  ASSERT_TRUE(n.send("WATCHDOG=1").is_ok());
  EXPECT_EQ(r.next(), "READY=1");
  EXPECT_EQ(r.next(), "STATUS=searching, 0 scans");
  EXPECT_EQ(r.next(), "WATCHDOG=1");
  EXPECT_EQ(r.next(50), "");
  EXPECT_EQ(n.sent(), 3u);
}

TEST(SdNotify, SendsToAnAbstractSocket) {
  Receiver r;
  ASSERT_TRUE(r.bind_to("@mmlfw_sd_notify_abstract_" + std::to_string(::getpid())));
  SdNotify n;
  ASSERT_TRUE(n.open(r.name.c_str(), nullptr, nullptr, 42).is_ok());
  EXPECT_EQ(n.watchdog_period_ns(), 0u);  // no WatchdogSec: no watchdog
  ASSERT_TRUE(n.send("READY=1").is_ok());
  EXPECT_EQ(r.next(), "READY=1");
}

TEST(SdNotify, ReadsTheEnvironment) {
  Receiver r;
  ASSERT_TRUE(r.bind_to(temp_socket_path("env")));
  ::setenv("NOTIFY_SOCKET", r.name.c_str(), 1);
  ::setenv("WATCHDOG_USEC", "500000", 1);
  ::setenv("WATCHDOG_PID", std::to_string(::getpid()).c_str(), 1);
  SdNotify n;
  const fw::Status st = n.open_from_env();
  ::unsetenv("NOTIFY_SOCKET");
  ::unsetenv("WATCHDOG_USEC");
  ::unsetenv("WATCHDOG_PID");
  ASSERT_TRUE(st.is_ok()) << st.message();
  EXPECT_EQ(n.watchdog_period_ns(), 500000000ull);
  ASSERT_TRUE(n.send("WATCHDOG=1").is_ok());
  EXPECT_EQ(r.next(), "WATCHDOG=1");
}

TEST(SdNotify, AnotherProcesssWatchdogIsNotFed) {
  Receiver r;
  ASSERT_TRUE(r.bind_to(temp_socket_path("pid")));
  SdNotify n;
  ASSERT_TRUE(n.open(r.name.c_str(), "500000", "4242", 42).is_ok());
  EXPECT_TRUE(n.enabled());
  EXPECT_EQ(n.watchdog_period_ns(), 0u);
}

TEST(SdNotify, WithoutNotifySocketEverySendIsANoOp) {
  SdNotify n;
  ASSERT_TRUE(n.open(nullptr, "500000", nullptr, 42).is_ok());
  EXPECT_FALSE(n.enabled());
  EXPECT_TRUE(n.send("READY=1").is_ok());
  EXPECT_EQ(n.sent(), 0u);
}

TEST(SdNotify, MalformedVariablesAreErrorsNamingThem) {
  SdNotify n;
  fw::Status st = n.open("relative/socket", nullptr, nullptr, 42);
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), "NOTIFY_SOCKET 'relative/socket'"), nullptr) << st.message();
  st = n.open("/run/systemd/notify", "2s", nullptr, 42);
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), "WATCHDOG_USEC '2s'"), nullptr) << st.message();
  st = n.open("/run/systemd/notify", "0", nullptr, 42);
  EXPECT_FALSE(st.is_ok());
  st = n.open("/run/systemd/notify", "1000", "pid", 42);
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), "WATCHDOG_PID 'pid'"), nullptr) << st.message();
  const std::string too_long = "/" + std::string(120, 'x');
  EXPECT_FALSE(n.open(too_long.c_str(), nullptr, nullptr, 42).is_ok());
}

TEST(SdNotify, AGoneReceiverFailsTheSendNamingTheSocket) {
  const std::string path = temp_socket_path("gone");
  {
    Receiver r;
    ASSERT_TRUE(r.bind_to(path));
  }  // receiver closed and unlinked
  SdNotify n;
  ASSERT_TRUE(n.open(path.c_str(), nullptr, nullptr, 42).is_ok());
  const fw::Status st = n.send("READY=1");
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(std::strstr(st.message(), path.c_str()), nullptr) << st.message();
  EXPECT_EQ(n.failed(), 1u);
}

}  // namespace
}  // namespace hal_linux
