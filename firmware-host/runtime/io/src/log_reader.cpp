// Streaming log reader: one line at a time through zlib (which reads plain files as they
// are), format detection from content, and the tinySLAM and DP-SLAM line formats.
#include <zlib.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "carmen_parse.h"
#include "log_parse.h"
#include "bag_common.h"
#include "sdpslam/io/log_reader.h"
#include "sdpslam/core/det_math.h"

namespace sdpslam::io {
namespace {

constexpr double kPi = 3.14159265358979323846;

// tinySLAM / BreezySLAM exp2.dat layout, 0-based fields (BreezySLAM examples/log2pgm.py:
// toks[0] timestamp, toks[2], toks[3] odometry Q1, Q2, toks[24:] distances; it drops the
// line's last field): 24 header fields, then 682 URG-04LX ranges for steps 44..725.
constexpr std::size_t kTinyStampField = 0;
constexpr std::size_t kTinyLeftTicksField = 2;
constexpr std::size_t kTinyRightTicksField = 3;
constexpr std::size_t kTinyFirstRangeField = 24;
constexpr std::uint32_t kTinyBeams = 682;
// URG-04LX geometry (protocols.md section 1): angle = (step - 384) * 2 pi / 1024.
constexpr int kUrgFirstStep = 44;
constexpr int kUrgFrontStep = 384;
constexpr double kUrgStepsPerRev = 1024.0;
constexpr int kUrgMinValidMm = 20;  // below: error codes, never ranges
constexpr float kUrgRangeMinM = 0.02F;
constexpr float kUrgRangeMaxM = 5.6F;

// DP-SLAM sample logs carry no time: one scan per 100 ms is synthesised.
constexpr std::int64_t kDpSlamPeriodUs = 100000;

// Reads lines through gzread. Lines longer than kMaxLineBytes are cut off and flagged
// (the rest of such a line is discarded up to its newline).
class LineSource {
 public:
  ~LineSource() { close(); }

  bool open(const std::string& path, std::string* error) {
    file_ = gzopen(path.c_str(), "rb");
    if (file_ == nullptr) {
      *error = path + ": cannot open: " + (errno != 0 ? std::strerror(errno) : "out of memory");
      return false;
    }
    gzbuffer(file_, kReadChunkBytes);
    // Left uninitialised: gzread fills it, and only the bytes it reports are read.
    if (buf_ == nullptr) buf_.reset(new char[kReadChunkBytes]);
    return true;
  }

  void close() {
    if (file_ != nullptr) gzclose(file_);
    file_ = nullptr;
  }

  // False at the end of input. *overlong is set for a line longer than kMaxLineBytes (its
  // first kMaxLineBytes bytes are in *line). A read error ends the input with *read_error.
  bool next(std::string* line, bool* overlong) {
    line->clear();
    *overlong = false;
    bool any = false;
    for (;;) {
      if (pos_ == len_) {
        if (!fill()) return any;
      }
      const char* start = buf_.get() + pos_;
      const std::size_t avail = len_ - pos_;
      const void* nl = std::memchr(start, '\n', avail);
      const std::size_t take = nl != nullptr ? static_cast<std::size_t>(static_cast<const char*>(nl) - start) : avail;
      any = true;
      if (!*overlong) {
        const std::size_t room = detail::kMaxLineBytes + 1 - line->size();
        if (take < room) {
          line->append(start, take);
        } else {
          line->append(start, room - 1);
          *overlong = true;
        }
      }
      pos_ += take;
      if (nl != nullptr) {
        ++pos_;
        break;
      }
    }
    if (!line->empty() && line->back() == '\r') line->pop_back();
    return true;
  }

  const std::string& read_error() const { return read_error_; }
  std::uint64_t offset() const {
    if (file_ == nullptr) return 0;
    const z_off_t off = gzoffset(file_);
    return off > 0 ? static_cast<std::uint64_t>(off) : 0U;
  }

 private:
  bool fill() {
    if (file_ == nullptr || eof_) return false;
    const int got = gzread(file_, buf_.get(), kReadChunkBytes);
    if (got <= 0) {
      eof_ = true;
      int errnum = Z_OK;
      const char* msg = gzerror(file_, &errnum);
      if (got < 0 || (errnum != Z_OK && errnum != Z_STREAM_END)) {
        read_error_ = errnum == Z_BUF_ERROR ? "compressed input ends early (truncated .gz)"
                                            : std::string("read error: ") + (msg != nullptr ? msg : "unknown");
      }
      return false;
    }
    pos_ = 0;
    len_ = static_cast<std::size_t>(got);
    return true;
  }

  gzFile file_ = nullptr;
  static constexpr unsigned kReadChunkBytes = 64U * 1024U;
  std::unique_ptr<char[]> buf_;
  std::size_t pos_ = 0;
  std::size_t len_ = 0;
  bool eof_ = false;
  std::string read_error_;
};

bool is_carmen_keyword(std::string_view k) {
  static constexpr const char* kKnown[] = {"PARAM",     "ODOM",      "FLASER",    "RLASER",    "ROBOTLASER1",
                                           "ROBOTLASER2", "SYNC",    "TRUEPOS",   "RAWLASER1", "RAWLASER2",
                                           "RAWLASER3", "RAWLASER4", "SONAR",     "BUMPER",    "SCANMARK",
                                           "POSITIONLASER", "IMU",   "GPSNMEA"};
  for (const char* name : kKnown) {
    if (k == name) return true;
  }
  return k.rfind("NMEA-", 0) == 0;
}

// The format a line belongs to, or kAuto when it tells nothing.
LogFormat classify_line(const std::vector<std::string_view>& f) {
  if (f.empty() || f[0][0] == '#') return LogFormat::kAuto;
  if (is_carmen_keyword(f[0])) return LogFormat::kCarmen;
  if (f[0] == "Odometry" || f[0] == "Laser") return LogFormat::kDpSlam;
  std::int64_t v = 0;
  if (f.size() >= kTinyFirstRangeField + kTinyBeams && detail::parse_int(f[0], &v)) return LogFormat::kTinySlam;
  return LogFormat::kAuto;
}

}  // namespace

struct LogReader::Impl {
  LogReaderOptions options;
  std::string path;
  LineSource source;
  std::unique_ptr<detail::BagSource> bag;  // formats kRosBag, kRos2Bag
  LogFormat format = LogFormat::kAuto;
  std::string line;
  std::vector<std::string_view> fields;
  std::string reason;
  std::int64_t line_no = 0;
  std::vector<LogError> errors;
  std::size_t error_count = 0;
  std::size_t warning_count = 0;
  bool read_error_reported = false;

  LaserRecord laser;
  OdomRecord odom;
  ParamRecord param;

  // tinySLAM odometry integration state.
  bool ticks_latched = false;
  std::int64_t last_left_ticks = 0;
  std::int64_t last_right_ticks = 0;
  Pose2 wheel_pose;

  // DP-SLAM state.
  std::int64_t dp_scan_index = 0;
  bool dp_have_odom = false;
  Pose2 dp_odom;

  // Reversed-odometry repair (LogReader::next()): the last velocity-carrying pose as
  // written and as repaired.
  bool repair_latched = false;
  bool repair_active = false;  // a repair happened: poses go through the repaired chain
  Pose2 repair_last_raw;
  Pose2 repair_last_pose;
  std::size_t repairs = 0;

  // Plausibility (LogReader::next()), per message type (ODOM, FLASER and the other
  // front lasers, RLASER, ROBOTLASER1): types interleave with stamps of their own
  // sources, and a laser line may carry an odometry pose older than its stamp.
  struct TypeState {
    std::int64_t last_stamp_us = 0;
    bool latched_stamp = false;
    bool latched = false;
    Pose2 last_pose;  // the last odometry pose returned for this type
  };
  TypeState types[4];
  Pose2 jump_offset;  // odometry returned = jump_offset ∘ odometry as written
  std::size_t jumps_removed = 0;
  std::size_t stamps_backwards = 0;
  std::int64_t first_backwards_line = 0;

  TypeState& type_of(Next got) {
    if (got == Next::kOdom) return types[0];
    if (laser.keyword == "RLASER") return types[2];
    if (laser.keyword == "ROBOTLASER1") return types[3];
    return types[1];
  }

  // The odometry pose of a record on the chain without impossible jumps; reports one.
  Pose2 plausible(TypeState& t, const Pose2& written, std::int64_t stamp_us, bool has_stamp) {
    Pose2 out = jump_offset.compose(written);
    if (t.latched && t.latched_stamp && has_stamp) {
      const std::int64_t gap_us = stamp_us > t.last_stamp_us ? stamp_us - t.last_stamp_us : t.last_stamp_us - stamp_us;
      const double dt_s = static_cast<double>(gap_us) * 1e-6;
      const Pose2 d = between(t.last_pose, out);
      const double dist_m = det::sqrt(d.x_m * d.x_m + d.y_m * d.y_m);
      const double turn_rad = d.heading_rad < 0.0 ? -d.heading_rad : d.heading_rad;
      constexpr double kSlackM = 0.5;
      constexpr double kSlackRad = 0.5;
      const bool too_fast = options.max_speed_mps > 0.0 && dist_m > options.max_speed_mps * dt_s + kSlackM;
      const bool turns_too_fast =
          options.max_turn_rate_radps > 0.0 && turn_rad > options.max_turn_rate_radps * dt_s + kSlackRad;
      if (too_fast || turns_too_fast) {
        char text[200];
        std::snprintf(text, sizeof text,
                      "odometry jumps %.3f m and %.3f rad in %.3f s (limits %.3g m/s, %.3g rad/s): not applied",
                      dist_m, turn_rad, dt_s, options.max_speed_mps, options.max_turn_rate_radps);
        add_error(line_no, text, false);
        ++jumps_removed;
        jump_offset = t.last_pose.compose(written.inverse());
        out = t.last_pose;
      }
    }
    t.latched = true;
    t.last_pose = out;
    return out;
  }
  // One record's place in its type's sequence: a laser stamped before the previous one
  // of its type is counted (the log is processed in file order, the order its sensors
  // delivered; trajectories keep the stamps as written), an impossible odometry jump is
  // removed, and the record's stamp becomes the type's latest.
  void sequence_record(Next got) {
    if (got == Next::kOdom) {
      odom.pose = plausible(types[0], odom.pose, odom.stamp_us, true);
      types[0].last_stamp_us = odom.stamp_us;
      types[0].latched_stamp = true;
      return;
    }
    if (got != Next::kLaser) return;
    TypeState& t = type_of(got);
    if (laser.has_stamp && t.latched_stamp && laser.stamp_us < t.last_stamp_us) {
      if (stamps_backwards == 0U) first_backwards_line = line_no;
      ++stamps_backwards;
    }
    if (laser.has_odom_pose) {
      const Pose2 written = laser.odom_pose;
      laser.odom_pose = plausible(t, written, laser.stamp_us, laser.has_stamp);
      if (laser.has_laser_pose) laser.laser_pose = laser.odom_pose.compose(between(written, laser.laser_pose));
    }
    if (laser.has_stamp) {
      t.last_stamp_us = laser.stamp_us;
      t.latched_stamp = true;
    }
  }

  // The increment's forward component, from the raw coordinate differences: exactly 0
  // when the position did not change (an in-place turn), where between()'s rotation
  // would leave a rounding residue of either sign.
  static bool against_velocity(const Pose2& from, const Pose2& to, double tv_mps) {
    const double forward_m =
        det::cos(from.heading_rad) * (to.x_m - from.x_m) + det::sin(from.heading_rad) * (to.y_m - from.y_m);
    return (tv_mps < 0.0 && forward_m > 0.0) || (tv_mps > 0.0 && forward_m < 0.0);
  }
  static Pose2 mirrored(const Pose2& d) { return Pose2{-d.x_m, -d.y_m, d.heading_rad}; }

  // A pose with its measured velocity: advances the chain.
  Pose2 repair_with_velocity(const Pose2& raw, double tv_mps) {
    Pose2 out = raw;
    if (repair_latched) {
      Pose2 d = between(repair_last_raw, raw);
      if (against_velocity(repair_last_raw, raw, tv_mps)) {
        d = mirrored(d);
        ++repairs;
        repair_active = true;
      }
      if (repair_active) out = repair_last_pose.compose(d);
    }
    repair_latched = true;
    repair_last_raw = raw;
    repair_last_pose = out;
    return out;
  }
  // A pose without a velocity (a laser's odometry pose): moved with the correction of
  // the last velocity-carrying pose. Its small offset from that pose is kept as written:
  // the laser may be stamped before or after it, so that offset is not a motion the
  // velocity measured.
  Pose2 repair_without_velocity(const Pose2& raw) const {
    if (!repair_active) return raw;
    return repair_last_pose.compose(between(repair_last_raw, raw));
  }
  void repair_record(Next got) {
    if (got == Next::kOdom) {
      odom.pose = repair_with_velocity(odom.pose, odom.tv_mps);
      return;
    }
    if (got != Next::kLaser || !laser.has_odom_pose) return;
    const Pose2 raw = laser.odom_pose;
    laser.odom_pose = laser.has_tv ? repair_with_velocity(raw, laser.tv_mps) : repair_without_velocity(raw);
    if (repair_active && laser.has_laser_pose) laser.laser_pose = laser.odom_pose.compose(between(raw, laser.laser_pose));
  }

  void add_error(std::int64_t at_line, std::string why, bool warning) {
    ++error_count;
    if (warning) ++warning_count;
    if (errors.size() < options.max_errors_kept) errors.push_back(LogError{path, at_line, std::move(why), warning});
  }

  void apply_param(const ParamRecord& p) {
    // Only well-formed numbers are taken; anything else leaves the option as it was.
    double v = 0.0;
    if (!detail::parse_finite(p.value, &v)) return;
    if (p.name == "robot_frontlaser_offset") options.front_laser_offset_m = v;
    if (p.name == "robot_rearlaser_offset") options.rear_laser_offset_m = v;
    if (v > 0.0 && (p.name == "robot_frontlaser_max" || p.name == "robot_front_laser_max")) {
      options.front_laser_max_m = static_cast<float>(v);
    }
    if (v > 0.0 && (p.name == "robot_rearlaser_max" || p.name == "robot_rear_laser_max")) {
      options.rear_laser_max_m = static_cast<float>(v);
    }
  }

  Next parse_tinyslam() {
    const std::size_t want = kTinyFirstRangeField + kTinyBeams;
    // The published file has one more field after the ranges, which BreezySLAM drops.
    if (fields.size() != want && fields.size() != want + 1) {
      reason = "tinySLAM line needs " + std::to_string(want) + " or " + std::to_string(want + 1) +
               " fields, found " + std::to_string(fields.size());
      return Next::kEnd;
    }
    std::int64_t stamp_us = 0;
    std::int64_t left = 0;
    std::int64_t right = 0;
    if (!detail::parse_int(fields[kTinyStampField], &stamp_us)) {
      reason = "timestamp (field 1) is not an integer: " + detail::quote(fields[kTinyStampField]);
      return Next::kEnd;
    }
    if (!detail::parse_int(fields[kTinyLeftTicksField], &left) ||
        !detail::parse_int(fields[kTinyRightTicksField], &right)) {
      reason = "wheel ticks (fields 3, 4) are not integers";
      return Next::kEnd;
    }
    RangeScan& scan = laser.scan;
    for (std::uint32_t b = 0; b < kTinyBeams; ++b) {
      const std::size_t i = kTinyFirstRangeField + b;
      std::int64_t mm = 0;
      if (!detail::parse_int(fields[i], &mm) || mm < 0 || mm > 1000000) {
        reason = "range " + std::to_string(b) + " (field " + std::to_string(i + 1) +
                 ") is not a millimetre count: " + detail::quote(fields[i]);
        return Next::kEnd;
      }
      scan.ranges_m[b] = mm < kUrgMinValidMm ? 0.0F : static_cast<float>(mm) / 1000.0F;
    }
    scan.beam_count = kTinyBeams;
    scan.geometry.angle_min_rad =
        static_cast<float>(static_cast<double>(kUrgFirstStep - kUrgFrontStep) * 2.0 * kPi / kUrgStepsPerRev);
    scan.geometry.angle_increment_rad = static_cast<float>(2.0 * kPi / kUrgStepsPerRev);
    scan.geometry.range_min_m = kUrgRangeMinM;
    scan.geometry.range_max_m = kUrgRangeMaxM;
    scan.geometry.laser_in_base = Pose2{options.tinyslam_laser_offset_m, 0.0, 0.0};
    scan.stamp_us = stamp_us;

    // Differential drive, integrated along the arc (protocols.md section 4); the first
    // sample is latched, never integrated.
    if (!ticks_latched) {
      ticks_latched = true;
      wheel_pose = Pose2{};
    } else {
      const WheelOdometryParams& w = options.wheels;
      const double rad_per_tick = 2.0 * kPi / w.ticks_per_rev;
      const double dl_m = static_cast<double>(left - last_left_ticks) * rad_per_tick * w.wheel_radius_m;
      const double dr_m = static_cast<double>(right - last_right_ticks) * rad_per_tick * w.wheel_radius_m;
      const double ds = (dl_m + dr_m) / 2.0;
      const double dth = (dr_m - dl_m) / w.wheel_separation_m;
      const double th = wheel_pose.heading_rad;
      if (std::fabs(dth) < 1e-6) {
        wheel_pose.x_m += ds * std::cos(th);
        wheel_pose.y_m += ds * std::sin(th);
      } else {
        wheel_pose.x_m += ds / dth * (std::sin(th + dth) - std::sin(th));
        wheel_pose.y_m -= ds / dth * (std::cos(th + dth) - std::cos(th));
      }
      wheel_pose.heading_rad = normalize_angle_rad(th + dth);
    }
    last_left_ticks = left;
    last_right_ticks = right;

    laser.keyword = "tinyslam";
    laser.stamp_us = stamp_us;
    laser.logger_stamp_us = 0;
    laser.has_stamp = true;
    laser.has_laser_pose = false;
    laser.laser_pose = Pose2{};
    laser.odom_pose = wheel_pose;
    laser.has_odom_pose = true;
    return Next::kLaser;
  }

  Next parse_dpslam() {
    const std::string_view k = fields[0];
    if (k == "Odometry") {
      if (fields.size() != 4) {
        reason = "Odometry needs 4 fields, found " + std::to_string(fields.size());
        return Next::kEnd;
      }
      double v[3];
      for (std::size_t i = 0; i < 3; ++i) {
        if (!detail::parse_finite(fields[i + 1], &v[i])) {
          reason = "Odometry field " + std::to_string(i + 2) + " is not a finite number: " +
                   detail::quote(fields[i + 1]);
          return Next::kEnd;
        }
      }
      dp_odom = Pose2{v[0], v[1], v[2]};
      dp_have_odom = true;
      odom = OdomRecord{};
      odom.pose = dp_odom;
      odom.stamp_us = dp_scan_index * kDpSlamPeriodUs;  // the stamp the next scan gets
      return Next::kOdom;
    }
    if (k != "Laser") {
      reason = "expected 'Odometry' or 'Laser', found " + detail::quote(k);
      return Next::kEnd;
    }
    std::int64_t n = 0;
    if (fields.size() < 2 || !detail::parse_int(fields[1], &n)) {
      reason = "Laser beam count (field 2) is missing or not an integer";
      return Next::kEnd;
    }
    if (n < 2 || n > static_cast<std::int64_t>(capacity::kMaxBeams)) {
      reason = "Laser beam count " + std::to_string(n) + " is outside [2, " + std::to_string(capacity::kMaxBeams) + "]";
      return Next::kEnd;
    }
    if (fields.size() != static_cast<std::size_t>(n) + 2U) {
      reason = "Laser with " + std::to_string(n) + " readings needs " + std::to_string(n + 2) + " fields, found " +
               std::to_string(fields.size());
      return Next::kEnd;
    }
    RangeScan& scan = laser.scan;
    for (std::int64_t b = 0; b < n; ++b) {
      const std::size_t i = 2U + static_cast<std::size_t>(b);
      float r = 0.0F;
      if (!detail::parse_finite(fields[i], &r) || r < 0.0F) {
        reason = "range " + std::to_string(b) + " (field " + std::to_string(i + 1) +
                 ") is not a finite non-negative number: " + detail::quote(fields[i]);
        return Next::kEnd;
      }
      scan.ranges_m[b] = r;
    }
    scan.beam_count = static_cast<std::uint32_t>(n);
    scan.geometry.angle_min_rad = static_cast<float>(-kPi / 2.0);
    scan.geometry.angle_increment_rad = static_cast<float>(kPi / static_cast<double>(n - 1));
    scan.geometry.range_min_m = 0.0F;
    scan.geometry.range_max_m = options.default_range_max_m;
    scan.geometry.laser_in_base = Pose2{};
    laser.keyword = "dpslam";
    laser.stamp_us = dp_scan_index * kDpSlamPeriodUs;
    scan.stamp_us = laser.stamp_us;
    laser.logger_stamp_us = 0;
    laser.has_stamp = false;
    laser.has_laser_pose = false;
    laser.laser_pose = Pose2{};
    laser.odom_pose = dp_odom;
    laser.has_odom_pose = dp_have_odom;
    ++dp_scan_index;
    return Next::kLaser;
  }
};

LogReader::LogReader() : impl_(std::make_unique<Impl>()) {}
LogReader::~LogReader() = default;

bool LogReader::open(const std::string& path, const LogReaderOptions& options, std::string* error) {
  impl_ = std::make_unique<Impl>();
  impl_->options = options;
  impl_->path = path;
  std::string local_error;
  std::string* err = error != nullptr ? error : &local_error;
  LogFormat format = options.format;
  if (format == LogFormat::kAuto && detail::looks_like_rosbag(path)) format = LogFormat::kRosBag;
  if (format == LogFormat::kAuto && detail::looks_like_ros2_bag(path)) format = LogFormat::kRos2Bag;
  if (format == LogFormat::kRosBag || format == LogFormat::kRos2Bag) {
    const detail::BagSourceMaker make =
        format == LogFormat::kRosBag ? detail::g_make_ros1_source : detail::g_make_ros2_source;
    if (make == nullptr) {
      *err = path + ": a " + (format == LogFormat::kRosBag ? "ROS 1" : "ROS 2") +
             " bag, and this program reads no bags (the sdpslam command does)";
      return false;
    }
    impl_->bag = make(err);
    if (impl_->bag == nullptr || !impl_->bag->open(path, options, err)) return false;
    impl_->format = format;
    return true;
  }
  if (format == LogFormat::kAuto) {
    // A first pass over the head of the file; the first line that names a format decides.
    constexpr int kDetectLines = 100;
    LineSource probe;
    if (!probe.open(path, err)) return false;
    std::string line;
    bool overlong = false;
    std::vector<std::string_view> fields;
    for (int i = 0; i < kDetectLines && format == LogFormat::kAuto && probe.next(&line, &overlong); ++i) {
      if (overlong || !detail::check_text(line).empty()) continue;
      detail::split_fields(line, &fields);
      format = classify_line(fields);
    }
    if (format == LogFormat::kAuto) {
      *err = path + ": cannot detect the log format from its first " + std::to_string(kDetectLines) +
             " lines (expected CARMEN keywords, 'Odometry'/'Laser' lines, or tinySLAM numeric lines)" +
             (probe.read_error().empty() ? "" : "; " + probe.read_error());
      return false;
    }
  }
  if (!impl_->source.open(path, err)) return false;
  impl_->format = format;
  return true;
}

LogReader::Next LogReader::next() {
  Impl& s = *impl_;
  if (s.format == LogFormat::kAuto) return Next::kEnd;  // not open
  if (s.bag != nullptr) {
    for (;;) {
      bool warning = false;
      const detail::BagSource::Got got = s.bag->next(&s.laser, &s.reason, &warning, &s.line_no);
      if (got == detail::BagSource::Got::kEnd) return Next::kEnd;
      if (!s.reason.empty()) s.add_error(s.line_no, s.reason, warning);
      if (got == detail::BagSource::Got::kSkipped) continue;
      s.sequence_record(Next::kLaser);
      s.laser.line = s.line_no;
      return Next::kLaser;
    }
  }
  bool overlong = false;
  while (s.source.next(&s.line, &overlong)) {
    ++s.line_no;
    if (overlong) {
      s.add_error(s.line_no, "line longer than " + std::to_string(detail::kMaxLineBytes) + " bytes", false);
      continue;
    }
    std::string bad = detail::check_text(s.line);
    if (!bad.empty()) {
      s.add_error(s.line_no, bad, false);
      continue;
    }
    detail::split_fields(s.line, &s.fields);
    if (s.fields.empty() || s.fields[0][0] == '#') continue;
    s.reason.clear();
    Next got = Next::kEnd;
    switch (s.format) {
      case LogFormat::kCarmen:
        got = detail::parse_carmen_fields(s.fields, s.options, &s.laser, &s.odom, &s.param, &s.reason);
        break;
      case LogFormat::kTinySlam: got = s.parse_tinyslam(); break;
      case LogFormat::kDpSlam: got = s.parse_dpslam(); break;
      case LogFormat::kAuto:
      case LogFormat::kRosBag:
      case LogFormat::kRos2Bag: break;
    }
    if (!s.reason.empty()) {
      const bool warning = s.reason.rfind(detail::kUnknownTypePrefix, 0) == 0;
      s.add_error(s.line_no, s.reason, warning);
      continue;
    }
    if (got == Next::kEnd) continue;  // an ignored message type
    if (s.format == LogFormat::kCarmen) s.repair_record(got);
    s.sequence_record(got);
    switch (got) {
      case Next::kLaser: s.laser.line = s.line_no; break;
      case Next::kOdom: s.odom.line = s.line_no; break;
      case Next::kParam:
        s.param.line = s.line_no;
        s.apply_param(s.param);
        break;
      case Next::kEnd: break;
    }
    return got;
  }
  if (!s.source.read_error().empty() && !s.read_error_reported) {
    s.read_error_reported = true;
    s.add_error(s.line_no + 1, s.source.read_error(), false);
  }
  return Next::kEnd;
}

const LaserRecord& LogReader::laser() const { return impl_->laser; }
const OdomRecord& LogReader::odom() const { return impl_->odom; }
const ParamRecord& LogReader::param() const { return impl_->param; }
LogFormat LogReader::format() const { return impl_->format; }
const std::vector<LogError>& LogReader::errors() const { return impl_->errors; }
std::size_t LogReader::error_count() const { return impl_->error_count; }
std::size_t LogReader::warning_count() const { return impl_->warning_count; }
std::size_t LogReader::odometry_reversals_repaired() const { return impl_->repairs; }
std::size_t LogReader::odometry_jumps_removed() const { return impl_->jumps_removed; }
std::size_t LogReader::scans_stamped_backwards() const { return impl_->stamps_backwards; }
std::int64_t LogReader::first_backwards_line() const { return impl_->first_backwards_line; }
std::int64_t LogReader::lines_read() const { return impl_->line_no; }
std::uint64_t LogReader::input_offset() const {
  return impl_->bag != nullptr ? impl_->bag->offset() : impl_->source.offset();
}
std::string LogReader::source_description() const {
  return impl_->bag != nullptr ? impl_->bag->description() : std::string();
}

bool read_whole_log(const std::string& path, const LogReaderOptions& options, LogContents* out, std::string* error) {
  *out = LogContents{};
  LogReader reader;
  if (!reader.open(path, options, error)) return false;
  for (;;) {
    const LogReader::Next n = reader.next();
    if (n == LogReader::Next::kEnd) break;
    switch (n) {
      case LogReader::Next::kLaser: out->lasers.push_back(reader.laser()); break;
      case LogReader::Next::kOdom: out->odoms.push_back(reader.odom()); break;
      case LogReader::Next::kParam: out->params.push_back(reader.param()); break;
      case LogReader::Next::kEnd: break;
    }
  }
  out->errors = reader.errors();
  out->error_count = reader.error_count();
  out->warning_count = reader.warning_count();
  out->format = reader.format();
  return true;
}

}  // namespace sdpslam::io
