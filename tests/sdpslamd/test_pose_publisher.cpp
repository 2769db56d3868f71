// The live pose socket (pose_publisher.h): the record's layout, subscriptions and their
// limits, clients that go away, and a full client that never blocks the publisher.
#include <CppUTest/TestHarness.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <string>

#include "sdpslam/daemon/pose_publisher.h"
#include "shared_data.h"

using sdpslam::Pose2;
using sdpslam::daemon::PosePublisher;
using sdpslam::daemon::PoseRecord;

namespace {

// A client as tools/examples/pose_client.py is: a datagram socket bound to its own path.
struct Client {
  int fd = -1;
  std::string path;
  explicit Client(const std::string& p) : path(p) {
    fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_NONBLOCK, 0);
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strcpy(a.sun_path, p.c_str());
    CHECK(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
  }
  ~Client() { close(); }
  void close() {
    if (fd >= 0) {
      ::close(fd);
      ::unlink(path.c_str());
      fd = -1;
    }
  }
  void send(const std::string& server, const char* text) const {
    sockaddr_un a{};
    a.sun_family = AF_UNIX;
    std::strcpy(a.sun_path, server.c_str());
    CHECK(::sendto(fd, text, std::strlen(text), 0, reinterpret_cast<sockaddr*>(&a), sizeof a) ==
          static_cast<ssize_t>(std::strlen(text)));
  }
  // The next record, false when none waits.
  bool receive(PoseRecord* r) const {
    unsigned char buf[128];
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    return n > 0 && sdpslam::daemon::decode_pose_record(buf, static_cast<std::size_t>(n), r);
  }
};

PoseRecord record_at(double x) {
  PoseRecord r;
  r.flags = PoseRecord::kFlagProcessed;
  r.map_version = 3U;
  r.stamp_us = 1234567890123LL;
  r.pose = Pose2{x, -2.5, 0.75};
  r.var_x = 0.01F;
  r.cov_xy = -0.002F;
  r.var_y = 0.02F;
  r.var_heading = 0.0004F;
  return r;
}

}  // namespace

TEST_GROUP(PosePublisher) {
  std::string dir;
  void setup() override { dir = sdpslam::test::make_temp_dir("pose"); }
};

TEST(PosePublisher, the_record_has_the_documented_layout) {
  unsigned char b[PoseRecord::kBytes];
  PoseRecord r = record_at(1.5);
  r.sequence = 7U;
  sdpslam::daemon::encode_pose_record(r, b);
  CHECK(std::memcmp(b, "SDPP", 4) == 0);
  LONGS_EQUAL(1, b[4] | (b[5] << 8));   // version
  LONGS_EQUAL(1, b[6] | (b[7] << 8));   // flags: processed
  LONGS_EQUAL(7, b[8]);                 // sequence, little-endian
  LONGS_EQUAL(3, b[12]);                // map version
  std::int64_t stamp;
  std::memcpy(&stamp, b + 16, 8);       // (this test runs on little-endian machines)
  LONGS_EQUAL(1234567890123LL, stamp);
  double x;
  std::memcpy(&x, b + 24, 8);
  DOUBLES_EQUAL(1.5, x, 0.0);
  float var_heading;
  std::memcpy(&var_heading, b + 60, 4);
  DOUBLES_EQUAL(0.0004F, var_heading, 0.0);
  PoseRecord back;
  CHECK_TRUE(sdpslam::daemon::decode_pose_record(b, sizeof b, &back));
  LONGS_EQUAL(7, back.sequence);
  DOUBLES_EQUAL(-2.5, back.pose.y_m, 0.0);
  DOUBLES_EQUAL(-0.002F, back.cov_xy, 0.0);
  CHECK_FALSE(sdpslam::daemon::decode_pose_record(b, sizeof b - 1U, &back));
  b[4] = 2;
  CHECK_FALSE(sdpslam::daemon::decode_pose_record(b, sizeof b, &back));
}

TEST(PosePublisher, subscribers_get_every_record_in_order_until_they_leave) {
  PosePublisher pub;
  std::string error;
  const std::string server = dir + "/pose.sock";
  CHECK_TEXT(pub.open(server, &error), error.c_str());
  pub.publish(record_at(0.0));  // nobody listens yet: published to no one
  Client a(dir + "/a.sock");
  Client b(dir + "/b.sock");
  a.send(server, "SUBSCRIBE");
  b.send(server, "SUBSCRIBE");
  b.send(server, "SUBSCRIBE");  // twice: still one subscription
  pub.poll();
  LONGS_EQUAL(2, pub.subscribers());
  pub.publish(record_at(1.0));
  pub.publish(record_at(2.0));
  PoseRecord r;
  for (const Client* c : {&a, &b}) {
    CHECK_TRUE(c->receive(&r));
    LONGS_EQUAL(2, r.sequence);  // the first went to no one
    DOUBLES_EQUAL(1.0, r.pose.x_m, 0.0);
    CHECK_TRUE(c->receive(&r));
    LONGS_EQUAL(3, r.sequence);
    DOUBLES_EQUAL(2.0, r.pose.x_m, 0.0);
    CHECK_FALSE(c->receive(&r));
  }
  b.send(server, "UNSUBSCRIBE");
  pub.poll();
  LONGS_EQUAL(1, pub.subscribers());
  a.close();  // gone without a word
  pub.publish(record_at(3.0));
  LONGS_EQUAL(0, pub.subscribers());
  LONGS_EQUAL(1, pub.stats().subscribers_lost);
  CHECK_FALSE(b.receive(&r));
  LONGS_EQUAL(4, pub.stats().records);
}

TEST(PosePublisher, a_full_client_costs_records_not_time_and_the_ninth_is_refused) {
  PosePublisher pub;
  std::string error;
  const std::string server = dir + "/pose.sock";
  CHECK_TEXT(pub.open(server, &error), error.c_str());
  Client slow(dir + "/slow.sock");
  slow.send(server, "SUBSCRIBE");
  pub.poll();
  // A client that never reads: its queue fills, then records are dropped for it.
  for (int k = 0; k < 2000; ++k) pub.publish(record_at(k));
  CHECK(pub.stats().datagrams_dropped > 0U);
  CHECK(pub.stats().datagrams_sent > 0U);
  LONGS_EQUAL(2000, pub.stats().datagrams_sent + pub.stats().datagrams_dropped);
  LONGS_EQUAL(1, pub.subscribers());  // still subscribed
  Client* more[PosePublisher::kMaxSubscribers];
  for (std::size_t k = 0; k < PosePublisher::kMaxSubscribers; ++k) {
    more[k] = new Client(dir + "/c" + std::to_string(k) + ".sock");
    more[k]->send(server, "SUBSCRIBE");
  }
  pub.poll();
  LONGS_EQUAL(PosePublisher::kMaxSubscribers, pub.subscribers());
  LONGS_EQUAL(1, pub.stats().subscribers_refused);
  for (Client* c : more) delete c;
}

TEST(PosePublisher, a_path_too_long_or_in_a_missing_folder_is_refused_with_the_reason) {
  PosePublisher pub;
  std::string error;
  CHECK_FALSE(pub.open(std::string(200, 'x'), &error));
  CHECK_TEXT(error.find("longer than") != std::string::npos, error.c_str());
  CHECK_FALSE(pub.open(dir + "/missing/pose.sock", &error));
  CHECK_TEXT(error.find("cannot bind") != std::string::npos, error.c_str());
}
