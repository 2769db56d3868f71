#pragma once
// CAN frames in the layout replay-can writes: per 10 ms period one SYNC and the TPDO1 of
// each wheel (CANopen CiA 301/402 position, ../shared/docs/protocols.md), all three with
// the period's stamp. Used by the player's test and its benchmark.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/candump_log.h"

namespace sdpslam::replay::test {

inline std::vector<drivers::CandumpRecord> synthetic_frames(std::size_t periods) {
  std::vector<drivers::CandumpRecord> v;
  for (std::size_t k = 0; k < periods; ++k) {
    drivers::CandumpRecord r;
    r.stamp_us = 1700000000000000LL + static_cast<std::int64_t>(k) * 10000;
    r.has_stamp = true;
    r.frame = drivers::canopen::make_sync();
    v.push_back(r);
    drivers::canopen::make_tpdo1_position(1, static_cast<std::uint32_t>(k), 4, r.frame);
    v.push_back(r);
    drivers::canopen::make_tpdo1_position(2, static_cast<std::uint32_t>(3 * k), 4, r.frame);
    v.push_back(r);
  }
  return v;
}

}  // namespace sdpslam::replay::test
