// Writes the candump the virtual-CAN replay test plays: the first N lines of a tinySLAM
// log's real wheel ticks as CANopen SYNC + TPDO1 frames (nodes 1 and 2), the same
// conversion `sdpslam replay-can` does. Usage: hil_make_candump LOG N OUT.candump
// Exit 77 when LOG is absent (the shared data set is not beside the checkout).
#include <sys/stat.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "sdpslam/replay/encoder_frames.h"
#include "sdpslam/replay/tinyslam_ticks.h"

int main(int argc, char** argv) {
  using namespace sdpslam::replay;
  if (argc != 4) {
    std::fprintf(stderr, "usage: %s LOG N OUT.candump\n", argv[0]);
    return 2;
  }
  struct stat st{};
  if (::stat(argv[1], &st) != 0) {
    std::printf("SKIP: %s is absent (shared data sets live beside the checkout)\n", argv[1]);
    return 77;
  }
  TinySlamTicks t;
  std::string error;
  if (!read_tinyslam_ticks(argv[1], &t, &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 3;
  }
  const std::size_t n = std::strtoul(argv[2], nullptr, 10);
  if (t.samples.size() > n) t.samples.resize(n);
  EncoderFrameOptions o;
  std::snprintf(o.interface_name, sizeof o.interface_name, "vcan0");
  std::vector<sdpslam::drivers::CandumpRecord> frames;
  if (!tick_track_to_frames(t.samples, o, &frames, &error) || !write_candump_file(argv[3], frames, &error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 4;
  }
  std::printf("%zu samples, %zu frames -> %s\n", t.samples.size(), frames.size(), argv[3]);
  return 0;
}
