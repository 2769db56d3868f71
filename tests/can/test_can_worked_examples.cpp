// The shared CAN test vectors: can-worked-examples.log (candump -l syntax, values computed
// from CiA 301/406 and the ODrive docs) and canopen-bus-excerpt.txt (a real candump).
#include <CppUTest/TestHarness.h>

#include <vector>

#include "sdpslam/drivers/candump_log.h"
#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/odrive_codec.h"
#include "shared_data.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

namespace {
std::vector<CandumpRecord> read_all(const std::string& path, CandumpFormat format, CandumpReader& reader) {
  std::vector<CandumpRecord> out;
  CHECK_TRUE(reader.open(path.c_str()));
  CandumpRecord r;
  int rc;
  while ((rc = reader.next(r)) != 0) {
    if (rc < 0) {
      FAIL(("line " + std::to_string(reader.line_number()) + ": " + to_string(reader.error())).c_str());
    }
    out.push_back(r);
  }
  (void)format;
  return out;
}
}  // namespace

TEST_GROUP(WorkedExamples) {
  std::vector<CandumpRecord> recs;
  CandumpReader reader{CandumpFormat::kLog};
  void setup() override {
    recs = read_all(test::shared_path("testdata/sensors/can-worked-examples.log"), CandumpFormat::kLog, reader);
  }
  void teardown() override { recs.clear(); recs.shrink_to_fit(); }
};

TEST(WorkedExamples, all_thirteen_frames_parse_and_comments_are_skipped) {
  LONGS_EQUAL(13, recs.size());
  CHECK_TRUE(reader.comments() >= 5);
  LONGS_EQUAL(1700000000000000LL, recs[0].stamp_us);
  STRCMP_EQUAL("can0", recs[0].interface_name);
}

TEST(WorkedExamples, nmt_start_all_and_start_node_5) {
  canopen::NmtCommand c{};
  std::uint8_t node = 99;
  CHECK(canopen::decode_nmt(recs[0].frame, c, node) == CanDecodeError::kOk);
  CHECK(c == canopen::NmtCommand::kStart);
  LONGS_EQUAL(0, node);
  CHECK(canopen::decode_nmt(recs[1].frame, c, node) == CanDecodeError::kOk);
  LONGS_EQUAL(5, node);
  hal::CanFrame built;
  canopen::make_nmt(canopen::NmtCommand::kStart, 5, built);
  MEMCMP_EQUAL(recs[1].frame.data, built.data, 2);
}

TEST(WorkedExamples, sync_has_no_data) {
  CHECK(canopen::decode_sync(recs[2].frame) == CanDecodeError::kOk);
  LONGS_EQUAL(0, recs[2].frame.dlc);
}

TEST(WorkedExamples, tpdo1_positions_of_nodes_5_and_6) {
  std::uint32_t pos = 0;
  CHECK(canopen::decode_tpdo1_position(recs[3].frame, 5, 4, pos) == CanDecodeError::kOk);
  LONGS_EQUAL(74565, pos);
  CHECK(canopen::decode_tpdo1_position(recs[4].frame, 6, 4, pos) == CanDecodeError::kOk);
  UNSIGNED_LONGS_EQUAL(0xFFFEDCBBu, pos);
}

TEST(WorkedExamples, heartbeats_operational_and_pre_operational) {
  canopen::NodeState st{};
  CHECK(canopen::decode_heartbeat(recs[5].frame, 5, st) == CanDecodeError::kOk);
  CHECK(st == canopen::NodeState::kOperational);
  CHECK(canopen::decode_heartbeat(recs[6].frame, 6, st) == CanDecodeError::kOk);
  CHECK(st == canopen::NodeState::kPreOperational);
}

TEST(WorkedExamples, emcy_node_5_code_8110_register_11) {
  canopen::Emergency e;
  CHECK(canopen::decode_emcy(recs[7].frame, 5, e) == CanDecodeError::kOk);
  LONGS_EQUAL(0x8110, e.error_code);
  LONGS_EQUAL(0x11, e.error_register);
}

TEST(WorkedExamples, odrive_rtr_request_matches_our_builder) {
  hal::CanFrame req;
  odrive::make_encoder_estimates_request(1, req);
  UNSIGNED_LONGS_EQUAL(req.id, recs[8].frame.id);
  LONGS_EQUAL(req.dlc, recs[8].frame.dlc);
}

TEST(WorkedExamples, odrive_estimates_1_5_turns_minus_2_turns_per_second) {
  odrive::EncoderEstimates est;
  CHECK(odrive::decode_encoder_estimates(recs[9].frame, 1, est) == CanDecodeError::kOk);
  DOUBLES_EQUAL(1.5, est.pos_turns, 0.0);
  DOUBLES_EQUAL(-2.0, est.vel_turns_s, 0.0);
}

TEST(WorkedExamples, odrive_heartbeat_closed_loop_no_error) {
  odrive::Heartbeat hb;
  CHECK(odrive::decode_heartbeat(recs[10].frame, 1, hb) == CanDecodeError::kOk);
  LONGS_EQUAL(0, hb.axis_error);
  LONGS_EQUAL(8, hb.axis_state);
}

TEST(WorkedExamples, vesc_frames_are_extended_and_unknown_to_both_protocols) {
  for (int i = 11; i <= 12; ++i) {
    const hal::CanFrame& f = recs[static_cast<std::size_t>(i)].frame;
    CHECK_TRUE(f.is_extended());
    CHECK(canopen::classify(f).kind == canopen::ObjectKind::kOther);
    odrive::EncoderEstimates est;
    CHECK(odrive::decode_encoder_estimates(f, 1, est) == CanDecodeError::kExtendedId);
  }
  LONGS_EQUAL(0x901, recs[11].frame.arbitration_id());
  LONGS_EQUAL(0x1B01, recs[12].frame.arbitration_id());
}

TEST_GROUP(CanOpenBusExcerpt) {
  std::vector<CandumpRecord> recs;
  CandumpReader reader{CandumpFormat::kScreen};
  void setup() override {
    recs = read_all(test::shared_path("testdata/sensors/canopen-bus-excerpt.txt"), CandumpFormat::kScreen, reader);
  }
  void teardown() override { recs.clear(); recs.shrink_to_fit(); }
};

TEST(CanOpenBusExcerpt, nine_frames_of_the_real_capture_parse) {
  LONGS_EQUAL(9, recs.size());
  LONGS_EQUAL(0, reader.errors());
}

TEST(CanOpenBusExcerpt, objects_classify_as_sync_sdo_bootup_emcy) {
  CHECK(canopen::classify(recs[0].frame).kind == canopen::ObjectKind::kSync);
  CHECK(canopen::classify(recs[1].frame).kind == canopen::ObjectKind::kSdoRx);
  CHECK(canopen::classify(recs[5].frame).kind == canopen::ObjectKind::kSdoTx);
  canopen::NodeState st = canopen::NodeState::kOperational;
  CHECK(canopen::decode_heartbeat(recs[4].frame, 0x20, st) == CanDecodeError::kOk);
  CHECK(st == canopen::NodeState::kBootUp);
}

TEST(CanOpenBusExcerpt, emcy_of_node_0x20_is_8110_register_11) {
  canopen::Emergency e;
  CHECK(canopen::decode_emcy(recs[6].frame, 0x20, e) == CanDecodeError::kOk);
  LONGS_EQUAL(0x8110, e.error_code);
  LONGS_EQUAL(0x11, e.error_register);
  CHECK(canopen::decode_emcy(recs[7].frame, 0x20, e) == CanDecodeError::kOk);
  LONGS_EQUAL(0x90, e.vendor[1]);
}
