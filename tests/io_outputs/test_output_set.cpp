// A run's outputs as one set: staged files arrive together with a manifest, a failed run
// leaves the previous set whole, leftovers of a killed run are removed, an unwritable
// folder fails at begin(), and a failed write names its errno.
#include <CppUTest/TestHarness.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>
#include <vector>

#include "sdpslam/io/atomic_file.h"
#include "sdpslam/io/output_set.h"
#include "file_tree.h"
#include "shared_data.h"

namespace {

using sdpslam::test::list_dir;
using sdpslam::test::read_file;
using sdpslam::test::remove_tree;

using sdpslam::io::ManifestEntry;
using sdpslam::io::OutputSet;

void put(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

// A process id no process can have: above Linux's largest (PID_MAX_LIMIT, 2^22).
constexpr long kDeadPid = 4194305L;

std::vector<std::string> manifest_names(const std::string& dir) {
  std::vector<ManifestEntry> entries;
  std::string error;
  CHECK_TRUE(sdpslam::io::read_manifest(dir, &entries, &error));
  std::vector<std::string> names;
  for (const ManifestEntry& e : entries) names.push_back(e.name);
  return names;
}

}  // namespace

TEST_GROUP(OutputSet) {
  std::string dir;
  void setup() override {
    dir = sdpslam::test::make_temp_dir("outset");
    CHECK(!dir.empty());
  }
  void teardown() override { remove_tree(dir); }
};

TEST(OutputSet, commit_delivers_every_file_with_a_manifest_that_checks) {
  std::string error;
  {
    OutputSet set;
    CHECK_TRUE(set.begin(dir, &error));
    CHECK_TRUE(sdpslam::io::write_file_atomic(set.path("b.txt"), "second\n", &error));
    CHECK_TRUE(sdpslam::io::write_file_atomic(set.path("a.txt"), "first\n", &error));
    // Nothing is visible in the folder before the commit.
    CHECK_TRUE(list_dir(dir).size() == 1U);
    CHECK_TRUE(set.commit(&error));
  }
  const std::vector<std::string> want = {"a.txt", "b.txt", "manifest.txt"};
  CHECK_TRUE(list_dir(dir) == want);  // the staging folder is gone
  std::vector<ManifestEntry> entries;
  CHECK_TRUE(sdpslam::io::read_manifest(dir, &entries, &error));
  LONGS_EQUAL(2, entries.size());
  for (const ManifestEntry& e : entries) {
    unsigned long long bytes = 0U;
    unsigned long crc = 0U;
    CHECK_TRUE(sdpslam::io::file_crc32(dir + "/" + e.name, &bytes, &crc, &error));
    CHECK_EQUAL(e.bytes, bytes);
    CHECK_EQUAL(e.crc32, crc);
  }
  STRCMP_EQUAL("a.txt", entries[0].name.c_str());
  CHECK_EQUAL(6ULL, entries[0].bytes);
}

TEST(OutputSet, a_new_set_replaces_the_previous_one_and_leaves_other_files_alone) {
  std::string error;
  put(dir + "/notes.txt", "the user's own file\n");
  {
    OutputSet set;
    CHECK_TRUE(set.begin(dir, &error));
    put(set.path("map.pgm"), "old map");
    put(set.path("icp_error.csv"), "old csv");
    CHECK_TRUE(set.commit(&error));
  }
  {
    OutputSet set;
    CHECK_TRUE(set.begin(dir, &error));
    put(set.path("map.pgm"), "new map");
    CHECK_TRUE(set.commit(&error));
  }
  // icp_error.csv belonged to the previous set only: removed. notes.txt was never listed.
  const std::vector<std::string> want = {"manifest.txt", "map.pgm", "notes.txt"};
  CHECK_TRUE(list_dir(dir) == want);
  STRCMP_EQUAL("new map", read_file(dir + "/map.pgm").c_str());
  CHECK_TRUE(manifest_names(dir) == std::vector<std::string>{"map.pgm"});
}

TEST(OutputSet, a_set_abandoned_before_commit_leaves_the_previous_set_whole) {
  std::string error;
  {
    OutputSet set;
    CHECK_TRUE(set.begin(dir, &error));
    put(set.path("trajectory.txt"), "old trajectory");
    put(set.path("map.pgm"), "old map");
    CHECK_TRUE(set.commit(&error));
  }
  {
    OutputSet set;  // a run that fails after writing part of its outputs
    CHECK_TRUE(set.begin(dir, &error));
    put(set.path("trajectory.txt"), "new trajectory");
  }
  const std::vector<std::string> want = {"manifest.txt", "map.pgm", "trajectory.txt"};
  CHECK_TRUE(list_dir(dir) == want);
  STRCMP_EQUAL("old trajectory", read_file(dir + "/trajectory.txt").c_str());
}

TEST(OutputSet, a_set_commits_again_for_periodic_outputs) {
  std::string error;
  OutputSet set;
  CHECK_TRUE(set.begin(dir, &error));
  put(set.path("trajectory.txt"), "one");
  CHECK_TRUE(set.commit(&error));
  put(set.path("trajectory.txt"), "two");
  CHECK_TRUE(set.commit(&error));
  STRCMP_EQUAL("two", read_file(dir + "/trajectory.txt").c_str());
  CHECK_TRUE(manifest_names(dir) == std::vector<std::string>{"trajectory.txt"});
}

TEST(OutputSet, leftovers_of_a_dead_process_are_removed_those_of_a_live_one_kept) {
  std::string error;
  const std::string dead = std::to_string(kDeadPid);
  const std::string live = std::to_string(static_cast<long>(::getppid()));
  put(dir + "/.map.pgm.tmp." + dead + ".0", "torn");
  put(dir + "/.stats.json.tmp." + dead + ".12", "torn");
  CHECK_EQUAL(0, ::mkdir((dir + "/.sdpslam-staging." + dead).c_str(), 0755));
  put(dir + "/.sdpslam-staging." + dead + "/trajectory.txt", "half a run");
  put(dir + "/.map.pgm.tmp." + live + ".3", "being written by another program");
  put(dir + "/.hidden.tmp.notes", "not ours: no pid");
  OutputSet set;
  CHECK_TRUE(set.begin(dir, &error));
  LONGS_EQUAL(3, set.stale_removed());
  const std::vector<std::string> left = list_dir(dir);
  CHECK_TRUE(std::find(left.begin(), left.end(), ".map.pgm.tmp." + live + ".3") != left.end());
  CHECK_TRUE(std::find(left.begin(), left.end(), ".hidden.tmp.notes") != left.end());
  LONGS_EQUAL(3, left.size());  // the two above and this set's staging folder
}

TEST(OutputSet, an_unwritable_folder_fails_at_begin_naming_it) {
  std::string error;
  std::string target = dir + "/locked";
  if (::geteuid() == 0) {
    target = "/proc";  // root may write everywhere a mode allows; /proc takes no new entries
  } else {
    CHECK_EQUAL(0, ::mkdir(target.c_str(), 0555));
  }
  OutputSet set;
  CHECK_FALSE(set.begin(target, &error));
  CHECK_TRUE(error.find("cannot write in output directory '" + target + "'") != std::string::npos);
}

TEST(OutputSet, a_malformed_manifest_is_named_with_its_line) {
  std::string error;
  put(dir + "/manifest.txt", "# comment\n12 0000abcd a.txt\n12 xyz b.txt\n");
  std::vector<ManifestEntry> entries;
  CHECK_FALSE(sdpslam::io::read_manifest(dir, &entries, &error));
  CHECK_TRUE(error.find("manifest.txt:3:") != std::string::npos);
  CHECK_TRUE(entries.empty());
}

// stdio does not keep the errno of a failed write; the atomic file does, so a full disk
// reads "No space left on device". The file-size limit gives the same path (EFBIG) on
// any machine.
TEST(OutputSet, a_failed_write_reports_its_own_errno) {
  std::string error;
  rlimit old {};
  CHECK_EQUAL(0, ::getrlimit(RLIMIT_FSIZE, &old));
  void (*old_handler)(int) = ::signal(SIGXFSZ, SIG_IGN);
  rlimit small = old;
  small.rlim_cur = 4096;
  CHECK_EQUAL(0, ::setrlimit(RLIMIT_FSIZE, &small));
  sdpslam::io::AtomicOutputFile out;
  bool opened = out.open(dir + "/big.txt", &error);
  if (opened) {
    for (int i = 0; i < 2000; ++i) std::fputs("0123456789\n", out.stream());
  }
  const bool committed = opened && out.commit(&error);
  ::setrlimit(RLIMIT_FSIZE, &old);
  ::signal(SIGXFSZ, old_handler);
  CHECK_TRUE(opened);
  CHECK_FALSE(committed);
  CHECK_TRUE(error.find("File too large") != std::string::npos);
  CHECK_TRUE(list_dir(dir).empty());  // the temporary is gone
}
