#include "sdpslam/replay/encoder_frames.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "sdpslam/drivers/canopen_codec.h"
#include "sdpslam/drivers/odrive_codec.h"

namespace sdpslam::replay {

Pose2 interpolate_pose(const std::vector<StampedPose>& poses, std::int64_t t_us) {
  if (t_us <= poses.front().stamp_us) return poses.front().pose;
  if (t_us >= poses.back().stamp_us) return poses.back().pose;
  std::size_t lo = 0;
  std::size_t hi = poses.size() - 1;
  while (hi - lo > 1) {  // poses[lo].stamp <= t < poses[hi].stamp
    const std::size_t mid = lo + (hi - lo) / 2;
    if (poses[mid].stamp_us <= t_us) lo = mid; else hi = mid;
  }
  const Pose2& a = poses[lo].pose;
  const Pose2& b = poses[hi].pose;
  const double f = static_cast<double>(t_us - poses[lo].stamp_us) /
                   static_cast<double>(poses[hi].stamp_us - poses[lo].stamp_us);
  const double dth = normalize_angle_rad(b.heading_rad - a.heading_rad);
  return Pose2{a.x_m + f * (b.x_m - a.x_m), a.y_m + f * (b.y_m - a.y_m),
               normalize_angle_rad(a.heading_rad + f * dth)};
}

bool poses_to_tick_track(const std::vector<StampedPose>& poses, const drivers::DiffDriveParams& params,
                         std::int64_t period_us, std::vector<TickSample>* out, std::size_t* dropped,
                         std::string* error) {
  out->clear();
  *dropped = 0;
  if (drivers::validate(params) != drivers::DiffDriveParamsError::kOk) {
    *error = std::string("invalid wheel parameters: ") + drivers::to_string(drivers::validate(params));
    return false;
  }
  if (period_us <= 0) {
    *error = "period must be > 0";
    return false;
  }
  std::vector<StampedPose> track;
  track.reserve(poses.size());
  for (const StampedPose& p : poses) {
    if (!track.empty() && p.stamp_us <= track.back().stamp_us) {
      ++*dropped;  // a repeated or backwards stamp cannot be placed in time
      continue;
    }
    track.push_back(p);
  }
  if (track.empty()) {
    *error = "no odometry poses";
    return false;
  }
  const std::int64_t t0 = track.front().stamp_us;
  const std::int64_t t1 = track.back().stamp_us;
  const std::size_t n = static_cast<std::size_t>((t1 - t0) / period_us) + 1U;
  std::vector<Pose2> sampled(n);
  std::vector<std::int64_t> left(n), right(n);
  for (std::size_t i = 0; i < n; ++i) {
    sampled[i] = interpolate_pose(track, t0 + static_cast<std::int64_t>(i) * period_us);
  }
  if (!drivers::poses_to_ticks(params, sampled.data(), n, left.data(), right.data())) {
    *error = "poses_to_ticks refused the track";
    return false;
  }
  out->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    (*out)[i] = TickSample{t0 + static_cast<std::int64_t>(i) * period_us, left[i], right[i]};
  }
  return true;
}

namespace {

drivers::CandumpRecord record(const hal::CanFrame& f, std::int64_t stamp_us, const char* iface) {
  drivers::CandumpRecord r;
  r.stamp_us = stamp_us;
  r.has_stamp = true;
  std::snprintf(r.interface_name, sizeof r.interface_name, "%s", iface);
  r.frame = f;
  return r;
}

}  // namespace

bool tick_track_to_frames(const std::vector<TickSample>& track, const EncoderFrameOptions& o,
                          std::vector<drivers::CandumpRecord>* out, std::string* error) {
  out->clear();
  const bool canopen = o.protocol == drivers::EncoderProtocol::kCanOpen;
  const std::uint8_t max_node = canopen ? drivers::canopen::kMaxNodeId : drivers::odrive::kMaxNodeId;
  if (o.left_node == 0 || o.right_node == 0 || o.left_node > max_node || o.right_node > max_node ||
      o.left_node == o.right_node) {
    *error = "node ids must differ and lie in 1.." + std::to_string(max_node);
    return false;
  }
  out->reserve(track.size() * (canopen && o.with_sync ? 3U : 2U));
  for (std::size_t i = 0; i < track.size(); ++i) {
    const TickSample& s = track[i];
    if (canopen) {
      if (o.with_sync) out->push_back(record(drivers::canopen::make_sync(), s.stamp_us, o.interface_name));
      hal::CanFrame l, r;
      drivers::canopen::make_tpdo1_position(o.left_node, static_cast<std::uint32_t>(s.left_ticks), 4, l);
      drivers::canopen::make_tpdo1_position(o.right_node, static_cast<std::uint32_t>(s.right_ticks), 4, r);
      out->push_back(record(l, s.stamp_us, o.interface_name));
      out->push_back(record(r, s.stamp_us, o.interface_name));
    } else {
      const double tpr = o.params.ticks_per_rev;
      drivers::odrive::EncoderEstimates el, er;
      el.pos_turns = static_cast<float>(static_cast<double>(s.left_ticks) / tpr);
      er.pos_turns = static_cast<float>(static_cast<double>(s.right_ticks) / tpr);
      if (i > 0 && s.stamp_us > track[i - 1].stamp_us) {
        // Raw counters and stamps may lie so far apart that their int64 difference
        // overflows. The stamp step is positive here, exact in uint64; the counter steps
        // are taken in double (exact below 2^53).
        auto diff = [](std::int64_t a, std::int64_t b) { return static_cast<double>(a) - static_cast<double>(b); };
        const std::uint64_t step_us =
            static_cast<std::uint64_t>(s.stamp_us) - static_cast<std::uint64_t>(track[i - 1].stamp_us);
        const double dt_s = static_cast<double>(step_us) * 1e-6;
        el.vel_turns_s = static_cast<float>(diff(s.left_ticks, track[i - 1].left_ticks) / tpr / dt_s);
        er.vel_turns_s = static_cast<float>(diff(s.right_ticks, track[i - 1].right_ticks) / tpr / dt_s);
      }
      hal::CanFrame l, r;
      drivers::odrive::make_encoder_estimates(o.left_node, el, l);
      drivers::odrive::make_encoder_estimates(o.right_node, er, r);
      out->push_back(record(l, s.stamp_us, o.interface_name));
      out->push_back(record(r, s.stamp_us, o.interface_name));
    }
  }
  return true;
}

bool write_candump_file(const std::string& path, const std::vector<drivers::CandumpRecord>& records,
                        std::string* error) {
  drivers::CandumpWriter w;
  if (!w.open(path.c_str())) {
    *error = path + ": cannot open for writing: " + std::strerror(errno);
    return false;
  }
  for (std::size_t i = 0; i < records.size(); ++i) {
    if (!w.write(records[i])) {
      *error = path + ": write of record " + std::to_string(i) + " failed";
      w.close();
      return false;
    }
  }
  if (!w.close()) {
    *error = path + ": close failed (disk full?)";
    return false;
  }
  return true;
}

std::size_t integrate_canopen_frames(const std::vector<drivers::CandumpRecord>& records,
                                     const drivers::DiffDriveParams& params, std::uint8_t left_node,
                                     std::uint8_t right_node, Pose2* pose_out) {
  drivers::DiffDriveOdometry odom(params);
  bool have_l = false, have_r = false;
  std::uint32_t l = 0, r = 0;
  std::int64_t stamp = 0;
  std::size_t pairs = 0;
  for (const drivers::CandumpRecord& rec : records) {
    std::uint32_t pos = 0;
    if (drivers::canopen::decode_tpdo1_position(rec.frame, left_node, 4, pos) == drivers::CanDecodeError::kOk) {
      l = pos;
      have_l = true;
    } else if (drivers::canopen::decode_tpdo1_position(rec.frame, right_node, 4, pos) ==
               drivers::CanDecodeError::kOk) {
      r = pos;
      have_r = true;
    } else {
      continue;
    }
    stamp = rec.stamp_us;
    if (have_l && have_r) {
      odom.update(l, r, stamp);
      have_l = have_r = false;
      ++pairs;
    }
  }
  *pose_out = odom.pose();
  return pairs;
}

}  // namespace sdpslam::replay
