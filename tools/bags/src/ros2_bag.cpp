// ROS 2 bags through libsqlite3 and Fast-CDR (sdpslam/io/bags.h, ros2_bag_source.h); part of
// the bag plugin (bag_common.h: BagPlugin).
#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <utility>
#include <vector>

#include "ros2_bag_source.h"
#include "sdpslam/io/atomic_file.h"

namespace sdpslam::io {
namespace fs = std::filesystem;
using eprosima::fastcdr::Cdr;
using eprosima::fastcdr::FastBuffer;

namespace {

constexpr const char* kLaserScanType = "sensor_msgs/msg/LaserScan";
constexpr const char* kOdometryType = "nav_msgs/msg/Odometry";
constexpr const char* kTfType = "tf2_msgs/msg/TFMessage";

// --- CDR (XCDR1, as rmw_fastrtps serialises ROS 2 messages) ---------------------------

struct Stamp {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
};

Stamp stamp_of(std::int64_t us) {
  std::int64_t sec = us / 1000000;
  std::int64_t rem = us % 1000000;
  if (rem < 0) {
    rem += 1000000;
    --sec;
  }
  return Stamp{static_cast<std::int32_t>(sec), static_cast<std::uint32_t>(rem * 1000)};
}

void put_header(Cdr& cdr, std::int64_t stamp_us, const std::string& frame) {
  const Stamp s = stamp_of(stamp_us);
  cdr << s.sec << s.nanosec << frame;
}

// The rotation about z by `yaw` as a quaternion (0, 0, z, w), nudged by a few ulps where
// needed so that detail::yaw_of() gives `yaw` back exactly: a log written as a bag and
// read back has the same headings, bit for bit (the quaternion stays a unit one to
// within those ulps).
void yaw_quaternion(double yaw, double* z, double* w) {
  const double z0 = std::sin(0.5 * yaw);
  const double w0 = std::cos(0.5 * yaw);
  *z = z0;
  *w = w0;
  if (detail::yaw_of(0.0, 0.0, z0, w0) == yaw) return;
  constexpr int kUlps = 16;
  const double inf = std::numeric_limits<double>::infinity();
  for (int dz = -kUlps; dz <= kUlps; ++dz) {
    double zc = z0;
    for (int k = 0; k < (dz < 0 ? -dz : dz); ++k) zc = std::nextafter(zc, dz < 0 ? -inf : inf);
    for (int dw = -kUlps; dw <= kUlps; ++dw) {
      double wc = w0;
      for (int k = 0; k < (dw < 0 ? -dw : dw); ++k) wc = std::nextafter(wc, dw < 0 ? -inf : inf);
      if (detail::yaw_of(0.0, 0.0, zc, wc) == yaw) {
        *z = zc;
        *w = wc;
        return;
      }
    }
  }
}

void put_pose(Cdr& cdr, const Pose2& p) {  // geometry_msgs Point/Vector3 + Quaternion
  const double zero = 0.0;
  double qz = 0.0;
  double qw = 1.0;
  yaw_quaternion(p.heading_rad, &qz, &qw);
  cdr << p.x_m << p.y_m << zero;
  cdr << zero << zero << qz << qw;
}

std::vector<unsigned char> finish(Cdr& cdr, FastBuffer& buffer) {
  const auto* data = reinterpret_cast<const unsigned char*>(buffer.getBuffer());
  return std::vector<unsigned char>(data, data + cdr.getSerializedDataLength());
}

std::vector<unsigned char> encode_scan(const LaserRecord& r, const std::string& frame) {
  FastBuffer buffer;
  Cdr cdr(buffer, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
  cdr.serialize_encapsulation();
  put_header(cdr, r.stamp_us, frame);
  const ScanGeometry& g = r.scan.geometry;
  const float angle_max =
      g.angle_min_rad + g.angle_increment_rad * static_cast<float>(r.scan.beam_count > 0U ? r.scan.beam_count - 1U : 0U);
  const float zero = 0.0F;
  cdr << g.angle_min_rad << angle_max << g.angle_increment_rad << zero << zero << g.range_min_m << g.range_max_m;
  const std::vector<float> ranges(r.scan.ranges_m, r.scan.ranges_m + r.scan.beam_count);
  const std::vector<float> intensities;
  cdr << ranges << intensities;
  return finish(cdr, buffer);
}

std::vector<unsigned char> encode_odometry(std::int64_t stamp_us, const Pose2& pose) {
  FastBuffer buffer;
  Cdr cdr(buffer, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
  cdr.serialize_encapsulation();
  put_header(cdr, stamp_us, "odom");
  cdr << std::string("base_link");
  put_pose(cdr, pose);
  const double covariance[36] = {};
  cdr.serializeArray(covariance, 36);
  const double zero = 0.0;
  for (int k = 0; k < 6; ++k) cdr << zero;  // twist: unknown, left at zero
  cdr.serializeArray(covariance, 36);
  return finish(cdr, buffer);
}

std::vector<unsigned char> encode_tf(const std::vector<detail::BagTransform>& ts) {
  FastBuffer buffer;
  Cdr cdr(buffer, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR);
  cdr.serialize_encapsulation();
  cdr << static_cast<std::uint32_t>(ts.size());
  for (const detail::BagTransform& t : ts) {
    put_header(cdr, t.stamp_us, t.parent);
    cdr << t.child;
    put_pose(cdr, t.pose);
  }
  return finish(cdr, buffer);
}

struct Decoder {
  FastBuffer buffer;
  Cdr cdr;
  Decoder(const void* data, std::size_t n)
      : buffer(const_cast<char*>(static_cast<const char*>(data)), n), cdr(buffer, Cdr::DEFAULT_ENDIAN, Cdr::DDS_CDR) {
    cdr.read_encapsulation();
  }
  std::int64_t header(std::string* frame) {
    std::int32_t sec = 0;
    std::uint32_t nanosec = 0;
    cdr >> sec >> nanosec >> *frame;
    return detail::stamp_us_of(sec, nanosec);
  }
  Pose2 pose() {
    double x = 0, y = 0, z = 0, qx = 0, qy = 0, qz = 0, qw = 0;
    cdr >> x >> y >> z >> qx >> qy >> qz >> qw;
    return Pose2{x, y, detail::yaw_of(qx, qy, qz, qw)};
  }
};

void decode_scan(const void* data, std::size_t n, detail::BagScan* s) {
  Decoder d(data, n);
  s->stamp_us = d.header(&s->frame);
  float angle_max = 0.0F, time_increment = 0.0F, scan_time = 0.0F;
  d.cdr >> s->angle_min >> angle_max >> s->angle_increment >> time_increment >> scan_time >> s->range_min >>
      s->range_max;
  d.cdr >> s->ranges;
}

void decode_odometry(const void* data, std::size_t n, std::int64_t* stamp_us, std::string* child, Pose2* pose) {
  Decoder d(data, n);
  std::string frame;
  *stamp_us = d.header(&frame);
  d.cdr >> *child;
  *pose = d.pose();
}

void decode_tf(const void* data, std::size_t n, std::vector<detail::BagTransform>* out) {
  Decoder d(data, n);
  std::uint32_t count = 0U;
  d.cdr >> count;
  out->clear();
  for (std::uint32_t k = 0; k < count; ++k) {
    detail::BagTransform t;
    t.stamp_us = d.header(&t.parent);
    d.cdr >> t.child;
    t.pose = d.pose();
    out->push_back(t);
  }
}

// --- SQLite ---------------------------------------------------------------------------

struct Db {
  sqlite3* db = nullptr;
  ~Db() {
    if (db != nullptr) sqlite3_close(db);
  }
  std::string error() const { return db != nullptr ? sqlite3_errmsg(db) : "out of memory"; }
};

struct Statement {
  sqlite3_stmt* st = nullptr;
  Statement() = default;
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  Statement(Statement&& o) noexcept : st(o.st) { o.st = nullptr; }
  Statement& operator=(Statement&& o) noexcept {
    if (this != &o) {
      if (st != nullptr) sqlite3_finalize(st);
      st = o.st;
      o.st = nullptr;
    }
    return *this;
  }
  ~Statement() {
    if (st != nullptr) sqlite3_finalize(st);
  }
  bool prepare(sqlite3* db, const char* sql) { return sqlite3_prepare_v2(db, sql, -1, &st, nullptr) == SQLITE_OK; }
};

}  // namespace

// --- writer ---------------------------------------------------------------------------

namespace {

struct WriterState {
  std::string folder;
  std::string partial;
  std::string db_name;
  Db db;
  Statement insert;
  bool open = false;
  bool have_odom = false;
  Pose2 last_odom;
  std::vector<std::pair<Pose2, std::string>> mounts;  // laser mounting -> frame
  std::vector<detail::BagTransform> statics;
  std::uint64_t counts[5] = {};  // by topic id 1..4
  std::int64_t first_ns = 0;
  std::int64_t last_ns = 0;
  std::uint64_t messages = 0U;
  std::uint64_t scans = 0U;
  std::uint64_t without_odom = 0U;

  bool write(int topic, std::int64_t stamp_us, const std::vector<unsigned char>& data, std::string* error) {
    const std::int64_t ns = stamp_us * 1000;
    sqlite3_reset(insert.st);
    sqlite3_bind_int(insert.st, 1, topic);
    sqlite3_bind_int64(insert.st, 2, ns);
    sqlite3_bind_blob(insert.st, 3, data.data(), static_cast<int>(data.size()), SQLITE_STATIC);
    if (sqlite3_step(insert.st) != SQLITE_DONE) {
      *error = partial + ": cannot write a message: " + db.error();
      return false;
    }
    if (messages == 0U || ns < first_ns) first_ns = ns;
    if (messages == 0U || ns > last_ns) last_ns = ns;
    ++messages;
    ++counts[topic];
    return true;
  }
};

class Ros2Writer final : public detail::BagWriter {
 public:
  Ros2Writer() = default;
  Ros2Writer(const Ros2Writer&) = delete;
  Ros2Writer& operator=(const Ros2Writer&) = delete;
  ~Ros2Writer() override;
  bool open(const std::string& folder, std::string* error) override;
  void odom(const OdomRecord& r) override;
  bool laser(const LaserRecord& r, std::string* error) override;
  std::uint64_t scans_written() const override { return state_.scans; }
  std::uint64_t scans_without_odometry() const override { return state_.without_odom; }
  bool close(std::string* error) override;

 private:
  WriterState state_;
};

Ros2Writer::~Ros2Writer() {
  if (state_.open) {
    state_.insert = Statement();
    if (state_.db.db != nullptr) {
      sqlite3_close(state_.db.db);
      state_.db.db = nullptr;
    }
    std::error_code ec;
    fs::remove_all(state_.partial, ec);
  }
}

bool Ros2Writer::open(const std::string& folder, std::string* error) {
  WriterState& s = state_;
  std::error_code ec;
  std::string name = fs::path(folder).filename().string();
  if (name.empty() || name == "." || name == "..") name = fs::path(folder).parent_path().filename().string();
  if (name.empty()) {
    *error = folder + ": not a folder name for a ROS 2 bag";
    return false;
  }
  if (fs::exists(folder, ec)) {
    *error = folder + ": exists already (a ROS 2 bag is a new folder)";
    return false;
  }
  s.folder = folder;
  s.partial = folder + ".partial";
  s.db_name = name + "_0.db3";
  fs::remove_all(s.partial, ec);  // a bag an earlier write left unfinished
  if (!fs::create_directories(s.partial, ec)) {
    *error = s.partial + ": cannot create: " + ec.message();
    return false;
  }
  s.open = true;
  const std::string db_path = s.partial + "/" + s.db_name;
  if (sqlite3_open_v2(db_path.c_str(), &s.db.db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) != SQLITE_OK) {
    *error = db_path + ": cannot create: " + s.db.error();
    return false;
  }
  // rosbag2's sqlite3 storage schema (Foxy to Humble), and its four topics.
  const char* schema =
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
      "data BLOB NOT NULL);"
      "CREATE INDEX timestamp_idx ON messages (timestamp ASC);"
      "INSERT INTO topics VALUES (1, '/scan', 'sensor_msgs/msg/LaserScan', 'cdr', '');"
      "INSERT INTO topics VALUES (2, '/odom', 'nav_msgs/msg/Odometry', 'cdr', '');"
      "INSERT INTO topics VALUES (3, '/tf', 'tf2_msgs/msg/TFMessage', 'cdr', '');"
      "INSERT INTO topics VALUES (4, '/tf_static', 'tf2_msgs/msg/TFMessage', 'cdr', '');"
      "BEGIN;";
  char* message = nullptr;
  if (sqlite3_exec(s.db.db, schema, nullptr, nullptr, &message) != SQLITE_OK ||
      !s.insert.prepare(s.db.db, "INSERT INTO messages (topic_id, timestamp, data) VALUES (?, ?, ?)")) {
    *error = db_path + ": cannot set up the bag: " + (message != nullptr ? message : s.db.error());
    sqlite3_free(message);
    return false;
  }
  return true;
}

void Ros2Writer::odom(const OdomRecord& r) {
  state_.last_odom = r.pose;
  state_.have_odom = true;
}

bool Ros2Writer::laser(const LaserRecord& r, std::string* error) {
  WriterState& s = state_;
  Pose2 odom = s.last_odom;
  if (r.has_odom_pose) {
    odom = r.odom_pose;
    s.last_odom = odom;
    s.have_odom = true;
  } else if (!s.have_odom) {
    ++s.without_odom;
    return true;
  }
  const Pose2& m = r.scan.geometry.laser_in_base;
  std::string frame;
  for (const auto& known : s.mounts) {
    if (std::memcmp(&known.first, &m, sizeof m) == 0) frame = known.second;
  }
  if (frame.empty()) {
    frame = s.mounts.empty() ? "laser" : "laser_" + std::to_string(s.mounts.size() + 1U);
    s.mounts.emplace_back(m, frame);
    s.statics.push_back(detail::BagTransform{r.stamp_us, "base_link", frame, m});
    if (!s.write(4, r.stamp_us, encode_tf(s.statics), error)) return false;
  }
  const std::vector<detail::BagTransform> tf{detail::BagTransform{r.stamp_us, "odom", "base_link", odom}};
  if (!s.write(1, r.stamp_us, encode_scan(r, frame), error) ||
      !s.write(2, r.stamp_us, encode_odometry(r.stamp_us, odom), error) ||
      !s.write(3, r.stamp_us, encode_tf(tf), error)) {
    return false;
  }
  ++s.scans;
  return true;
}

bool Ros2Writer::close(std::string* error) {
  WriterState& s = state_;
  if (!s.open) {
    *error = "the bag is not open";
    return false;
  }
  s.insert = Statement();
  char* message = nullptr;
  if (sqlite3_exec(s.db.db, "COMMIT;", nullptr, nullptr, &message) != SQLITE_OK) {
    *error = s.partial + ": cannot commit: " + (message != nullptr ? message : s.db.error());
    sqlite3_free(message);
    return false;
  }
  if (sqlite3_close(s.db.db) != SQLITE_OK) {
    *error = s.partial + ": cannot close: " + s.db.error();
    return false;
  }
  s.db.db = nullptr;
  const std::int64_t duration = s.messages > 0U ? s.last_ns - s.first_ns : 0;
  const char* names[5] = {"", "/scan", "/odom", "/tf", "/tf_static"};
  const char* types[5] = {"", kLaserScanType, kOdometryType, kTfType, kTfType};
  std::string y = "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n";
  y += "  duration:\n    nanoseconds: " + std::to_string(duration) + "\n";
  y += "  starting_time:\n    nanoseconds_since_epoch: " + std::to_string(s.first_ns) + "\n";
  y += "  message_count: " + std::to_string(s.messages) + "\n  topics_with_message_count:\n";
  for (int t = 1; t <= 4; ++t) {
    y += std::string("    - topic_metadata:\n        name: ") + names[t] + "\n        type: " + types[t] +
         "\n        serialization_format: cdr\n        offered_qos_profiles: \"\"\n      message_count: " +
         std::to_string(s.counts[t]) + "\n";
  }
  y += "  compression_format: \"\"\n  compression_mode: \"\"\n  relative_file_paths:\n    - " + s.db_name + "\n";
  y += "  files:\n    - path: " + s.db_name + "\n      starting_time:\n        nanoseconds_since_epoch: " +
       std::to_string(s.first_ns) + "\n      duration:\n        nanoseconds: " + std::to_string(duration) +
       "\n      message_count: " + std::to_string(s.messages) + "\n";
  if (!write_file_atomic(s.partial + "/metadata.yaml", y, error)) return false;
  std::error_code ec;
  fs::rename(s.partial, s.folder, ec);
  if (ec) {
    *error = s.folder + ": cannot move the bag into place: " + ec.message();
    return false;
  }
  s.open = false;
  const std::string parent = fs::path(s.folder).has_parent_path() ? fs::path(s.folder).parent_path().string() : ".";
  return fsync_directory(parent, error);
}

}  // namespace

namespace detail {
std::unique_ptr<BagWriter> make_ros2_writer() { return std::make_unique<Ros2Writer>(); }
bool ros2_bags_built() { return true; }
}  // namespace detail

// --- reader ---------------------------------------------------------------------------

namespace detail {

struct Ros2BagSource::Impl {
  struct File {
    std::string path;
    Db db;
    std::map<std::string, std::pair<int, std::string>> topics;  // name -> (id, type)
  };
  std::vector<std::unique_ptr<File>> files;
  BagScan scan;
  std::size_t file_index = 0U;
  Statement scans;

  // Every message of `topic`, in time order over the files: f(timestamp_ns, data, size).
  template <class F>
  bool each(const std::string& topic, std::string* error, F&& f) {
    for (auto& file : files) {
      auto t = file->topics.find(topic);
      if (t == file->topics.end()) continue;
      Statement st;
      if (!st.prepare(file->db.db, "SELECT timestamp, data FROM messages WHERE topic_id = ? ORDER BY timestamp, id")) {
        *error = file->path + ": " + file->db.error();
        return false;
      }
      sqlite3_bind_int(st.st, 1, t->second.first);
      while (sqlite3_step(st.st) == SQLITE_ROW) {
        f(sqlite3_column_int64(st.st, 0), sqlite3_column_blob(st.st, 1),
          static_cast<std::size_t>(sqlite3_column_bytes(st.st, 1)));
      }
    }
    return true;
  }

  // Positions `scans` on the next file that has the scan topic; false when none is left.
  bool start_file(const std::string& scan_topic) {
    for (; file_index < files.size(); ++file_index) {
      File& file = *files[file_index];
      auto t = file.topics.find(scan_topic);
      if (t == file.topics.end()) continue;
      scans = Statement();
      if (!scans.prepare(file.db.db, "SELECT timestamp, data FROM messages WHERE topic_id = ? ORDER BY timestamp, id")) {
        continue;
      }
      sqlite3_bind_int(scans.st, 1, t->second.first);
      return true;
    }
    return false;
  }
};

Ros2BagSource::Ros2BagSource() : impl_(std::make_unique<Impl>()) {}
Ros2BagSource::~Ros2BagSource() = default;

bool Ros2BagSource::open(const std::string& path, const LogReaderOptions& options, std::string* error) {
  Impl& s = *impl_;
  std::error_code ec;
  std::vector<std::string> paths;
  if (fs::is_directory(path, ec)) {
    const fs::path meta = fs::path(path) / "metadata.yaml";
    if (fs::exists(meta, ec)) {
      try {
        const YAML::Node root = YAML::LoadFile(meta.string());
        const YAML::Node files = root["rosbag2_bagfile_information"]["relative_file_paths"];
        if (files && files.IsSequence()) {
          for (const auto& f : files) paths.push_back((fs::path(path) / f.as<std::string>()).string());
        }
        const YAML::Node storage = root["rosbag2_bagfile_information"]["storage_identifier"];
        if (storage && storage.as<std::string>() != "sqlite3") {
          *error = meta.string() + ": storage '" + storage.as<std::string>() + "' (only sqlite3 bags are read)";
          return false;
        }
      } catch (const std::exception& e) {
        *error = meta.string() + ": " + e.what();
        return false;
      }
    }
    if (paths.empty()) {
      for (const auto& e : fs::directory_iterator(path, ec)) {
        if (e.path().extension() == ".db3") paths.push_back(e.path().string());
      }
      std::sort(paths.begin(), paths.end());
    }
  } else {
    paths.push_back(path);
  }
  if (paths.empty()) {
    *error = path + ": a ROS 2 bag folder without .db3 files";
    return false;
  }
  std::vector<std::pair<std::string, std::string>> topics;
  for (const std::string& p : paths) {
    auto file = std::make_unique<Impl::File>();
    file->path = p;
    if (sqlite3_open_v2(p.c_str(), &file->db.db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      *error = p + ": cannot open: " + file->db.error();
      return false;
    }
    Statement st;
    if (!st.prepare(file->db.db, "SELECT id, name, type, serialization_format FROM topics")) {
      *error = p + ": not a rosbag2 database: " + file->db.error();
      return false;
    }
    while (sqlite3_step(st.st) == SQLITE_ROW) {
      const auto text = [&](int c) {
        const unsigned char* v = sqlite3_column_text(st.st, c);
        return v != nullptr ? std::string(reinterpret_cast<const char*>(v)) : std::string();
      };
      const std::string name = text(1);
      const std::string type = text(2);
      if (text(3) != "cdr") continue;  // another serialisation: not readable here
      file->topics[name] = {sqlite3_column_int(st.st, 0), type};
      topics.emplace_back(name, type);
    }
    bag_bytes_ += static_cast<std::uint64_t>(fs::file_size(p, ec));
    s.files.push_back(std::move(file));
  }
  std::string odom_topic;
  if (!choose_topics(topics, kLaserScanType, kOdometryType, options, path, &odom_topic, error)) return false;
  std::string why;
  std::size_t bad = 0U;
  std::string first_bad;
  const auto note_bad = [&](const std::string& topic, const std::exception& e) {
    if (bad++ == 0U) first_bad = topic + ": " + e.what();
  };
  if (!odom_topic.empty()) {
    odom_source_ = odom_topic;
    bool child_named = false;
    if (!s.each(odom_topic, error, [&](std::int64_t, const void* data, std::size_t n) {
          try {
            std::int64_t stamp = 0;
            std::string child;
            Pose2 pose;
            decode_odometry(data, n, &stamp, &child, &pose);
            if (!child_named && !child.empty()) {
              assembler_.set_base_frame(child);
              child_named = true;
            }
            assembler_.add_odometry(stamp, pose);
          } catch (const std::exception& e) {
            note_bad(odom_topic, e);
          }
        })) {
      return false;
    }
  } else {
    const std::string tf_topic =
        choose_topic(topics, kTfType, std::string(), "/tf", "odometry", "--odom-topic", false, &why);
    if (tf_topic.empty() || tf_topic == "/tf_static") {
      *error = path + ": the bag has neither a " + kOdometryType + " topic nor " + kTfType +
               " odometry on /tf: no odometry";
      return false;
    }
    odom_source_ = tf_topic + " (" + options.bag_odom_frame + " -> " + assembler_.base_frame() + ")";
    std::vector<BagTransform> ts;
    if (!s.each(tf_topic, error, [&](std::int64_t, const void* data, std::size_t n) {
          try {
            decode_tf(data, n, &ts);
            for (const BagTransform& t : ts) {
              if (frame_name(t.parent) == options.bag_odom_frame && frame_name(t.child) == assembler_.base_frame()) {
                assembler_.add_odometry(t.stamp_us, t.pose);
              }
            }
          } catch (const std::exception& e) {
            note_bad(tf_topic, e);
          }
        })) {
      return false;
    }
  }
  if (!assembler_.finish_odometry()) {
    *error = path + ": no odometry messages in " + odom_source_ +
             (bad > 0U ? " (" + std::to_string(bad) + " did not decode; the first: " + first_bad + ")" : "");
    return false;
  }
  std::vector<BagTransform> ts;
  if (!s.each("/tf_static", error, [&](std::int64_t, const void* data, std::size_t n) {
        try {
          decode_tf(data, n, &ts);
          for (const BagTransform& t : ts) assembler_.add_static(t);
        } catch (const std::exception& e) {
          note_bad("/tf_static", e);
        }
      })) {
    return false;
  }
  if (!s.each(scan_topic_, error, [&](std::int64_t, const void*, std::size_t) { ++scan_count_; })) return false;
  s.start_file(scan_topic_);
  return true;
}

BagSource::Got Ros2BagSource::next(LaserRecord* laser, std::string* reason, bool* warning, std::int64_t* index) {
  Impl& s = *impl_;
  reason->clear();
  *warning = false;
  while (s.file_index < s.files.size()) {
    if (s.scans.st == nullptr || sqlite3_step(s.scans.st) != SQLITE_ROW) {
      ++s.file_index;
      s.scans = Statement();
      if (!s.start_file(scan_topic_)) return Got::kEnd;
      continue;
    }
    ++scans_read_;
    *index = static_cast<std::int64_t>(scans_read_);
    const std::int64_t receive_us = sqlite3_column_int64(s.scans.st, 0) / 1000;
    try {
      decode_scan(sqlite3_column_blob(s.scans.st, 1), static_cast<std::size_t>(sqlite3_column_bytes(s.scans.st, 1)),
                  &s.scan);
    } catch (const std::exception& e) {
      *reason = "scan message " + std::to_string(*index) + " does not decode as " + kLaserScanType + ": " + e.what();
      return Got::kSkipped;
    }
    if (!assembler_.to_record(s.scan, receive_us, laser, reason, warning)) {
      *reason = "scan message " + std::to_string(*index) + ": " + *reason;
      return Got::kSkipped;
    }
    return Got::kLaser;
  }
  return Got::kEnd;
}

}  // namespace detail
}  // namespace sdpslam::io
