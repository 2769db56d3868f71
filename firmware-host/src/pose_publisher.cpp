#include "sdpslam/daemon/pose_publisher.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace sdpslam::daemon {
namespace {

void put(unsigned char* p, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) p[i] = static_cast<unsigned char>(v >> (8 * i));
}
std::uint64_t get(const unsigned char* p, int bytes) {
  std::uint64_t v = 0U;
  for (int i = 0; i < bytes; ++i) v |= static_cast<std::uint64_t>(p[i]) << (8 * i);
  return v;
}
std::uint64_t bits(double d) {
  std::uint64_t u;
  std::memcpy(&u, &d, sizeof u);
  return u;
}
std::uint32_t bits(float f) {
  std::uint32_t u;
  std::memcpy(&u, &f, sizeof u);
  return u;
}
double as_double(std::uint64_t u) {
  double d;
  std::memcpy(&d, &u, sizeof d);
  return d;
}
float as_float(std::uint64_t u) {
  const auto v = static_cast<std::uint32_t>(u);
  float f;
  std::memcpy(&f, &v, sizeof f);
  return f;
}

bool same_address(const sockaddr_un& a, socklen_t al, const sockaddr_un& b, socklen_t bl) {
  return al == bl && std::memcmp(&a, &b, al) == 0;
}

}  // namespace

void encode_pose_record(const PoseRecord& r, unsigned char out[PoseRecord::kBytes]) {
  std::memcpy(out, "SDPP", 4);
  put(out + 4, PoseRecord::kVersion, 2);
  put(out + 6, r.flags, 2);
  put(out + 8, r.sequence, 4);
  put(out + 12, r.map_version, 4);
  put(out + 16, static_cast<std::uint64_t>(r.stamp_us), 8);
  put(out + 24, bits(r.pose.x_m), 8);
  put(out + 32, bits(r.pose.y_m), 8);
  put(out + 40, bits(r.pose.heading_rad), 8);
  put(out + 48, bits(r.var_x), 4);
  put(out + 52, bits(r.cov_xy), 4);
  put(out + 56, bits(r.var_y), 4);
  put(out + 60, bits(r.var_heading), 4);
}

bool decode_pose_record(const unsigned char* d, std::size_t n, PoseRecord* r) {
  if (n != PoseRecord::kBytes || std::memcmp(d, "SDPP", 4) != 0 || get(d + 4, 2) != PoseRecord::kVersion) return false;
  r->flags = static_cast<std::uint16_t>(get(d + 6, 2));
  r->sequence = static_cast<std::uint32_t>(get(d + 8, 4));
  r->map_version = static_cast<std::uint32_t>(get(d + 12, 4));
  r->stamp_us = static_cast<std::int64_t>(get(d + 16, 8));
  r->pose = Pose2{as_double(get(d + 24, 8)), as_double(get(d + 32, 8)), as_double(get(d + 40, 8))};
  r->var_x = as_float(get(d + 48, 4));
  r->cov_xy = as_float(get(d + 52, 4));
  r->var_y = as_float(get(d + 56, 4));
  r->var_heading = as_float(get(d + 60, 4));
  return true;
}

PosePublisher::~PosePublisher() {
  if (fd_ >= 0) {
    ::close(fd_);
    ::unlink(path_.c_str());
  }
}

bool PosePublisher::open(const std::string& path, std::string* error) {
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (path.empty() || path.size() >= sizeof addr.sun_path) {
    *error = "pose socket path '" + path + "' is empty or longer than " + std::to_string(sizeof addr.sun_path - 1U) +
             " bytes";
    return false;
  }
  std::memcpy(addr.sun_path, path.c_str(), path.size() + 1U);
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    *error = std::string("pose socket: ") + std::strerror(errno);
    return false;
  }
  struct stat st {};
  if (::lstat(path.c_str(), &st) == 0 && S_ISSOCK(st.st_mode)) ::unlink(path.c_str());  // a previous run's
  if (::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    *error = path + ": cannot bind the pose socket: " + std::strerror(errno);
    ::close(fd);
    return false;
  }
  // Clients run as this user or in its group (a datagram to a socket needs write access).
  if (::chmod(path.c_str(), 0660) != 0) {
    *error = path + ": cannot set the pose socket's mode: " + std::strerror(errno);
    ::close(fd);
    ::unlink(path.c_str());
    return false;
  }
  fd_ = fd;
  path_ = path;
  return true;
}

void PosePublisher::remove(std::size_t i) {
  subs_[i] = subs_[count_ - 1U];
  --count_;
}

void PosePublisher::poll() {
  if (fd_ < 0) return;
  for (;;) {
    char buf[32];
    Subscriber s{};
    s.len = sizeof s.addr;
    const ssize_t n = ::recvfrom(fd_, buf, sizeof buf, 0, reinterpret_cast<sockaddr*>(&s.addr), &s.len);
    if (n < 0) return;  // EAGAIN: nothing waiting
    if (s.len <= sizeof(sa_family_t)) continue;  // an unbound sender has no address to answer
    std::size_t found = count_;
    for (std::size_t i = 0; i < count_; ++i) {
      if (same_address(subs_[i].addr, subs_[i].len, s.addr, s.len)) found = i;
    }
    const bool unsubscribe = n >= 11 && std::memcmp(buf, "UNSUBSCRIBE", 11) == 0;
    if (unsubscribe) {
      if (found < count_) remove(found);
      continue;
    }
    if (found < count_) continue;  // already subscribed
    if (count_ == kMaxSubscribers) {
      ++stats_.subscribers_refused;
      continue;
    }
    subs_[count_++] = s;
    ++stats_.subscribes;
  }
}

void PosePublisher::publish(PoseRecord record) {
  if (fd_ < 0) return;
  record.sequence = ++sequence_;
  ++stats_.records;
  unsigned char bytes[PoseRecord::kBytes];
  encode_pose_record(record, bytes);
  for (std::size_t i = 0; i < count_;) {
    const ssize_t n = ::sendto(fd_, bytes, sizeof bytes, MSG_DONTWAIT | MSG_NOSIGNAL,
                               reinterpret_cast<const sockaddr*>(&subs_[i].addr), subs_[i].len);
    if (n == static_cast<ssize_t>(sizeof bytes)) {
      ++stats_.datagrams_sent;
    } else if (errno == ECONNREFUSED || errno == ENOENT || errno == ENOTCONN) {
      ++stats_.subscribers_lost;
      remove(i);
      continue;
    } else {
      ++stats_.datagrams_dropped;  // EAGAIN: the subscriber's queue is full
    }
    ++i;
  }
}

}  // namespace sdpslam::daemon
