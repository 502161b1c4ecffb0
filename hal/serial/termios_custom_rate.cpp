#include "termios_custom_rate.h"

#include <asm/termbits.h>
#include <errno.h>
#include <sys/ioctl.h>

namespace hal_serial {

int set_custom_rate(int fd, std::uint32_t baud, std::uint32_t* actual) {
  struct termios2 t {};
  if (::ioctl(fd, TCGETS2, &t) != 0) return errno;
  t.c_cflag &= ~static_cast<tcflag_t>(CBAUD);
  t.c_cflag |= BOTHER;
  t.c_cflag &= ~static_cast<tcflag_t>(CBAUD << IBSHIFT);
  t.c_cflag |= BOTHER << IBSHIFT;
  t.c_ispeed = baud;
  t.c_ospeed = baud;
  if (::ioctl(fd, TCSETS2, &t) != 0) return errno;
  struct termios2 back {};
  if (::ioctl(fd, TCGETS2, &back) != 0) return errno;
  *actual = back.c_ospeed;
  return 0;
}

}  // namespace hal_serial
