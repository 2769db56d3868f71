// Atomic replacement: the target is either the old or the new complete file, the
// temporary never survives a failure or an abandon, and errors name the path.
#include <CppUTest/TestHarness.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "sdpslam/io/atomic_file.h"
#include "file_tree.h"
#include "shared_data.h"

namespace {

using sdpslam::test::list_dir;
using sdpslam::test::read_file;
using sdpslam::test::remove_tree;

bool exists(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0;
}

}  // namespace

TEST_GROUP(AtomicFile) {
  std::string dir;
  void setup() override {
    dir = sdpslam::test::make_temp_dir("atomic");
    CHECK(!dir.empty());
  }
  void teardown() override { remove_tree(dir); }
};

TEST(AtomicFile, write_creates_file_with_exact_contents) {
  std::string error;
  const std::string path = dir + "/out.txt";
  const std::string contents("line 1\nbinary \0 byte\n", 21);
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, contents, &error));
  CHECK_TRUE(error.empty());
  CHECK(read_file(path) == contents);
  LONGS_EQUAL(1, list_dir(dir).size());
}

TEST(AtomicFile, write_replaces_existing_target_and_leaves_no_temporary) {
  std::string error;
  const std::string path = dir + "/out.txt";
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, "old contents, longer than the new\n", &error));
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, "new\n", &error));
  STRCMP_EQUAL("new\n", read_file(path).c_str());
  const auto names = list_dir(dir);
  LONGS_EQUAL(1, names.size());
  STRCMP_EQUAL("out.txt", names[0].c_str());
}

// kDurable flushes the file and its directory to storage (two fsyncs); kAtomicOnly
// replaces the file the same way (one whole file, no temporary left) without either.
TEST(AtomicFile, atomic_only_replaces_the_same_way_without_flushing_to_storage) {
  std::string error;
  const std::string path = dir + "/status.json";
  std::uint64_t before = sdpslam::io::fsync_count();
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, "{\"a\": 1}\n", &error));
  UNSIGNED_LONGLONGS_EQUAL(before + 2U, sdpslam::io::fsync_count());
  before = sdpslam::io::fsync_count();
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, "{\"a\": 2}\n", &error, sdpslam::io::Sync::kAtomicOnly));
  UNSIGNED_LONGLONGS_EQUAL(before, sdpslam::io::fsync_count());
  STRCMP_EQUAL("{\"a\": 2}\n", read_file(path).c_str());
  LONGS_EQUAL(1, list_dir(dir).size());
}

TEST(AtomicFile, empty_contents_give_an_empty_file) {
  std::string error;
  const std::string path = dir + "/empty";
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, "", &error));
  CHECK_TRUE(exists(path));
  LONGS_EQUAL(0, read_file(path).size());
}

TEST(AtomicFile, write_into_missing_directory_fails_naming_path_and_cause) {
  std::string error;
  const std::string path = dir + "/no/such/dir/out.txt";
  CHECK_FALSE(sdpslam::io::write_file_atomic(path, "x", &error));
  CHECK(error.find(path) != std::string::npos);
  CHECK(error.find("No such file or directory") != std::string::npos);
  LONGS_EQUAL(0, list_dir(dir).size());
}

// rename(2) cannot replace a directory with a file: the failure happens at the last step,
// after the whole new contents were written, so this proves the old target survives a
// late failure and the temporary is cleaned up (root ignores permission bits, so a
// read-only directory would not fail here).
TEST(AtomicFile, failed_rename_keeps_old_target_and_removes_temporary) {
  std::string error;
  const std::string path = dir + "/target";
  CHECK_EQUAL(0, ::mkdir(path.c_str(), 0755));
  CHECK_TRUE(sdpslam::io::write_file_atomic(path + "/keep", "old", &error));
  CHECK_FALSE(sdpslam::io::write_file_atomic(path, "new contents", &error));
  CHECK(error.find(path) != std::string::npos);
  CHECK(error.find("rename") != std::string::npos);
  STRCMP_EQUAL("old", read_file(path + "/keep").c_str());
  const auto names = list_dir(dir);
  LONGS_EQUAL(1, names.size());
  STRCMP_EQUAL("target", names[0].c_str());
}

TEST(AtomicFile, write_under_a_regular_file_fails_and_keeps_that_file) {
  std::string error;
  const std::string blocker = dir + "/plain";
  CHECK_TRUE(sdpslam::io::write_file_atomic(blocker, "keep me", &error));
  CHECK_FALSE(sdpslam::io::write_file_atomic(blocker + "/child", "x", &error));
  CHECK(error.find("Not a directory") != std::string::npos);
  STRCMP_EQUAL("keep me", read_file(blocker).c_str());
}

TEST(AtomicFile, streaming_file_is_invisible_until_commit) {
  std::string error;
  const std::string path = dir + "/stream.txt";
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, "old\n", &error));
  sdpslam::io::AtomicOutputFile out;
  CHECK_TRUE(out.open(path, &error));
  CHECK(out.stream() != nullptr);
  for (int i = 0; i < 1000; ++i) std::fprintf(out.stream(), "%d\n", i);
  std::fflush(out.stream());
  STRCMP_EQUAL("old\n", read_file(path).c_str());
  LONGS_EQUAL(2, list_dir(dir).size());  // target + temporary
  CHECK_TRUE(out.commit(&error));
  const std::string got = read_file(path);
  CHECK(got.rfind("0\n1\n2\n", 0) == 0);
  CHECK(got.size() > 3000);
  LONGS_EQUAL(1, list_dir(dir).size());
  CHECK(out.stream() == nullptr);
}

TEST(AtomicFile, temporary_is_hidden_and_named_after_target_and_pid) {
  std::string error;
  sdpslam::io::AtomicOutputFile out;
  CHECK_TRUE(out.open(dir + "/map.pgm", &error));
  const auto names = list_dir(dir);
  LONGS_EQUAL(1, names.size());
  const std::string prefix = ".map.pgm.tmp." + std::to_string(::getpid()) + ".";
  CHECK(names[0].rfind(prefix, 0) == 0);
  out.abandon();
}

TEST(AtomicFile, abandon_removes_temporary_and_keeps_target) {
  std::string error;
  const std::string path = dir + "/a.txt";
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, "old", &error));
  sdpslam::io::AtomicOutputFile out;
  CHECK_TRUE(out.open(path, &error));
  std::fputs("half-written", out.stream());
  out.abandon();
  STRCMP_EQUAL("old", read_file(path).c_str());
  LONGS_EQUAL(1, list_dir(dir).size());
  CHECK(out.stream() == nullptr);
}

TEST(AtomicFile, destroying_uncommitted_file_removes_temporary) {
  std::string error;
  {
    sdpslam::io::AtomicOutputFile out;
    CHECK_TRUE(out.open(dir + "/never.txt", &error));
    std::fputs("data", out.stream());
    LONGS_EQUAL(1, list_dir(dir).size());
  }
  LONGS_EQUAL(0, list_dir(dir).size());
}

TEST(AtomicFile, commit_without_open_is_refused) {
  std::string error;
  sdpslam::io::AtomicOutputFile out;
  CHECK_FALSE(out.commit(&error));
  CHECK_FALSE(error.empty());
}

TEST(AtomicFile, commit_after_write_error_fails_and_keeps_target) {
  std::string error;
  const std::string path = dir + "/w.txt";
  CHECK_TRUE(sdpslam::io::write_file_atomic(path, "old", &error));
  sdpslam::io::AtomicOutputFile out;
  CHECK_TRUE(out.open(path, &error));
  // Reading from a write-only stream sets its error flag, as a failed write would.
  std::fgetc(out.stream());
  CHECK(std::ferror(out.stream()) != 0);
  CHECK_FALSE(out.commit(&error));
  CHECK(error.find(path) != std::string::npos);
  STRCMP_EQUAL("old", read_file(path).c_str());
  LONGS_EQUAL(1, list_dir(dir).size());
}

TEST(AtomicFile, two_open_files_for_same_target_use_distinct_temporaries) {
  std::string error;
  sdpslam::io::AtomicOutputFile a;
  sdpslam::io::AtomicOutputFile b;
  CHECK_TRUE(a.open(dir + "/same", &error));
  CHECK_TRUE(b.open(dir + "/same", &error));
  LONGS_EQUAL(2, list_dir(dir).size());
  std::fputs("A", a.stream());
  std::fputs("B", b.stream());
  CHECK_TRUE(a.commit(&error));
  CHECK_TRUE(b.commit(&error));
  STRCMP_EQUAL("B", read_file(dir + "/same").c_str());
  LONGS_EQUAL(1, list_dir(dir).size());
}

TEST(AtomicFile, make_directories_creates_nested_path) {
  std::string error;
  const std::string nested = dir + "/a/b/c";
  CHECK_TRUE(sdpslam::io::make_directories(nested, &error));
  struct stat st {};
  CHECK_EQUAL(0, ::stat(nested.c_str(), &st));
  CHECK(S_ISDIR(st.st_mode));
  CHECK_TRUE(sdpslam::io::make_directories(nested + "/", &error));  // existing: fine
}

TEST(AtomicFile, make_directories_through_a_regular_file_fails) {
  std::string error;
  CHECK_TRUE(sdpslam::io::write_file_atomic(dir + "/f", "x", &error));
  CHECK_FALSE(sdpslam::io::make_directories(dir + "/f/sub", &error));
  CHECK(error.find(dir + "/f") != std::string::npos);
  CHECK(error.find("Not a directory") != std::string::npos);
}

TEST(AtomicFile, make_directories_refuses_empty_path) {
  std::string error;
  CHECK_FALSE(sdpslam::io::make_directories("", &error));
  CHECK_FALSE(error.empty());
}
