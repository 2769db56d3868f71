#pragma once
// Bridge to the termios2 ioctls. Kept in its own translation unit because <asm/termbits.h>
// and <termios.h> both define `struct termios` and cannot meet in one file.
#include <cstdint>

namespace sdpslam::drivers::detail {

// Sets both directions to `baud` with BOTHER (TCSETS2). 0 on success, else an errno value.
int set_termios2_baud(int fd, std::uint32_t baud);
// Output speed from TCGETS2, 0 on error.
std::uint32_t get_termios2_baud(int fd);

}  // namespace sdpslam::drivers::detail
