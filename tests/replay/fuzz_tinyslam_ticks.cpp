// libFuzzer: the tinySLAM ticks reader (replay::read_tinyslam_ticks, the .dat logs of
// `sdpslam replay-can`) over arbitrary file contents read from memory, then the encoder
// frames made from what was read, in both protocols, and their decoding back.
// Checks beyond the sanitizers: stamps of the samples strictly increase; the first
// counters are those of the first sample; every line is either a sample, a listed error
// or blank / a comment, and every error names "fuzz.dat:N:" with N a line of the input; a
// line holding a NUL byte (text hidden from the parser) is an error;
// CANopen frames carry the counters modulo 2^32 and decode back to them; ODrive frames
// carry finite turns.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/odrive_codec.h"
#include "sdpslam/replay/encoder_frames.h"
#include "sdpslam/replay/tinyslam_ticks.h"
#include "fuzz_text.h"

namespace {

using sdpslam::test::fuzz::check;
using sdpslam::test::fuzz::error_line;
using sdpslam::test::fuzz::line_count;

const char* const kName = "fuzz.dat";

std::size_t lines_with_nul(const std::string& text) {
  std::size_t n = 0;
  bool seen = false;
  for (char c : text) {
    if (c == '\0') seen = true;
    if (c == '\n') {
      n += seen ? 1U : 0U;
      seen = false;
    }
  }
  return n + (seen ? 1U : 0U);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::FILE* f = ::fmemopen(text.data(), text.size(), "r");
  if (f == nullptr) std::abort();
  sdpslam::replay::TinySlamTicks ticks;
  std::string error;
  const bool ok = sdpslam::replay::read_tinyslam_ticks(f, kName, &ticks, &error);
  std::fclose(f);
  const std::size_t lines = line_count(text);
  check(ticks.samples.size() + ticks.errors.size() <= lines);
  check(ticks.errors.size() >= lines_with_nul(text));
  std::size_t previous = 0;
  for (const std::string& e : ticks.errors) {
    const std::size_t n = error_line(e, kName);
    check(n != 0U);
    check(n > previous && n <= lines);
    previous = n;
  }
  if (!ok) {
    check(ticks.samples.empty() || error == std::string(kName) + ": read error");
    return 0;
  }
  check(!ticks.samples.empty());
  check(ticks.first_left_raw == ticks.samples.front().left_ticks);
  check(ticks.first_right_raw == ticks.samples.front().right_ticks);
  for (std::size_t i = 1; i < ticks.samples.size(); ++i) {
    check(ticks.samples[i].stamp_us > ticks.samples[i - 1].stamp_us);
  }

  sdpslam::replay::EncoderFrameOptions options;
  std::vector<sdpslam::drivers::CandumpRecord> frames;
  check(sdpslam::replay::tick_track_to_frames(ticks.samples, options, &frames, &error));
  check(frames.size() == 3U * ticks.samples.size());
  for (std::size_t i = 0; i < ticks.samples.size(); ++i) {
    std::uint32_t left = 0;
    std::uint32_t right = 0;
    check(sdpslam::drivers::canopen::decode_tpdo1_position(frames[3U * i + 1U].frame, options.left_node, 4, left) ==
          sdpslam::drivers::CanDecodeError::kOk);
    check(sdpslam::drivers::canopen::decode_tpdo1_position(frames[3U * i + 2U].frame, options.right_node, 4, right) ==
          sdpslam::drivers::CanDecodeError::kOk);
    check(left == static_cast<std::uint32_t>(ticks.samples[i].left_ticks));
    check(right == static_cast<std::uint32_t>(ticks.samples[i].right_ticks));
  }
  sdpslam::Pose2 pose;
  (void)sdpslam::replay::integrate_canopen_frames(frames, options.params, options.left_node, options.right_node, &pose);

  options.protocol = sdpslam::drivers::EncoderProtocol::kODrive;
  frames.clear();
  check(sdpslam::replay::tick_track_to_frames(ticks.samples, options, &frames, &error));
  check(frames.size() == 2U * ticks.samples.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    sdpslam::drivers::odrive::EncoderEstimates est;
    const std::uint8_t node = i % 2U == 0U ? options.left_node : options.right_node;
    check(sdpslam::drivers::odrive::decode_encoder_estimates(frames[i].frame, node, est) ==
          sdpslam::drivers::CanDecodeError::kOk);
    check(std::isfinite(est.pos_turns));
  }
  return 0;
}
