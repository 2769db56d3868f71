// libFuzzer target over the pure CAN codecs and the candump line parsers. Checks: no
// crash / UB (sanitizers), decoders never write output on error, and every log line that
// parses formats back to a line that parses to the same frame.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string_view>

#include "sdpslam/drivers/candump_log.h"
#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/diff_drive_odometry.h"
#include "sdpslam/drivers/odrive_codec.h"
#include "fuzz_text.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

namespace {

using sdpslam::test::fuzz::check;

void decode_everything(const hal::CanFrame& f, std::uint8_t node) {
  const canopen::ObjectId obj = canopen::classify(f);
  check(obj.node <= canopen::kMaxNodeId);
  std::uint32_t pos = 0xDEADBEEF;
  if (canopen::decode_tpdo1_position(f, node, 4, pos) != CanDecodeError::kOk) check(pos == 0xDEADBEEF);
  canopen::decode_tpdo1_position(f, node, 2, pos);
  canopen::NodeState st{};
  canopen::decode_heartbeat(f, node, st);
  canopen::Emergency e;
  canopen::decode_emcy(f, node, e);
  canopen::NmtCommand cmd{};
  std::uint8_t n = 0;
  canopen::decode_nmt(f, cmd, n);
  canopen::decode_sync(f);
  odrive::EncoderEstimates est;
  if (odrive::decode_encoder_estimates(f, static_cast<std::uint8_t>(node & 0x3F), est) == CanDecodeError::kOk) {
    check(est.pos_turns == est.pos_turns && est.vel_turns_s == est.vel_turns_s);
  }
  odrive::Heartbeat hb;
  odrive::decode_heartbeat(f, static_cast<std::uint8_t>(node & 0x3F), hb);
  (void)wrap_delta(f.data[0] | (f.data[1] << 8), f.data[2] | (f.data[3] << 8), 16);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);

  CandumpRecord rec;
  const CandumpParseResult r = parse_candump_log_line(line, rec);
  check(r.kind != CandumpLineKind::kError || (r.column >= 1 && r.column <= size + 1));
  if (r.kind == CandumpLineKind::kFrame) {
    check(rec.frame.dlc <= 8);
    decode_everything(rec.frame, rec.frame.data[0]);
    char buf[kMaxCandumpLogLine];
    const std::size_t n = format_candump_log_line(rec, buf, sizeof buf);
    check(n > 0 && n < sizeof buf);
    CandumpRecord back;
    check(parse_candump_log_line(std::string_view(buf, n), back).kind == CandumpLineKind::kFrame);
    check(back.frame.id == rec.frame.id && back.frame.dlc == rec.frame.dlc);
    check(back.stamp_us == rec.stamp_us);
    check(std::strcmp(back.interface_name, rec.interface_name) == 0);
    if (!rec.frame.is_rtr()) check(std::memcmp(back.frame.data, rec.frame.data, rec.frame.dlc) == 0);
  }
  CandumpRecord screen;
  const CandumpParseResult s = parse_candump_screen_line(line, screen);
  check(s.kind != CandumpLineKind::kError || (s.column >= 1 && s.column <= size + 1));
  if (s.kind == CandumpLineKind::kFrame) decode_everything(screen.frame, 5);

  // Raw bytes as a struct can_frame image: id (LE u32), dlc, 3 pad, 8 data.
  if (size >= 16) {
    hal::CanFrame f;
    f.id = static_cast<std::uint32_t>(data[0]) | (static_cast<std::uint32_t>(data[1]) << 8) |
           (static_cast<std::uint32_t>(data[2]) << 16) | (static_cast<std::uint32_t>(data[3]) << 24);
    f.dlc = data[4] > 8 ? 8 : data[4];
    std::memcpy(f.data, data + 8, 8);
    decode_everything(f, data[5]);
  }
  return 0;
}
