// Arbitrary line speeds through termios2 / BOTHER (Linux tty_ioctl(4)). This file must not
// include <termios.h> (see termios2_baud.h).
#include "termios2_baud.h"

#include <asm/termbits.h>
#include <sys/ioctl.h>

#include <cerrno>

namespace sdpslam::drivers::detail {

int set_termios2_baud(int fd, std::uint32_t baud) {
  struct termios2 tio {};
  if (ioctl(fd, TCGETS2, &tio) != 0) return errno;
  tio.c_cflag &= ~static_cast<tcflag_t>(CBAUD);
  tio.c_cflag |= BOTHER;
  tio.c_cflag &= ~static_cast<tcflag_t>(CBAUD << IBSHIFT);
  tio.c_cflag |= static_cast<tcflag_t>(BOTHER << IBSHIFT);
  tio.c_ispeed = baud;
  tio.c_ospeed = baud;
  if (ioctl(fd, TCSETS2, &tio) != 0) return errno;
  return 0;
}

std::uint32_t get_termios2_baud(int fd) {
  struct termios2 tio {};
  if (ioctl(fd, TCGETS2, &tio) != 0) return 0U;
  return tio.c_ospeed;
}

}  // namespace sdpslam::drivers::detail
