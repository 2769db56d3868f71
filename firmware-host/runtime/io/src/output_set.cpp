// One run's output files delivered as a set (see output_set.h).
#include "sdpslam/io/output_set.h"

#include <dirent.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "sdpslam/io/atomic_file.h"

namespace sdpslam::io {
namespace {

constexpr const char* kStagingPrefix = ".sdpslam-staging.";

void set_error(std::string* error, const std::string& what, const std::string& path, int err) {
  if (error != nullptr) *error = what + " '" + path + "': " + std::strerror(err);
}

// The decimal number that `text` is entirely made of; false when it is not one.
bool parse_pid(const std::string& text, long* pid) {
  if (text.empty() || text.size() > 10U) return false;
  long v = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  *pid = v;
  return v > 0;
}

// The process that created a temporary or staging folder, from its name; 0 when the name
// is not one of ours. `.NAME.tmp.PID.N` (AtomicOutputFile) or `.sdpslam-staging.PID`.
long owner_pid(const std::string& name) {
  long pid = 0;
  if (name.rfind(kStagingPrefix, 0) == 0) {
    return parse_pid(name.substr(std::strlen(kStagingPrefix)), &pid) ? pid : 0;
  }
  if (name.empty() || name[0] != '.') return 0;
  const std::size_t tmp = name.rfind(".tmp.");
  if (tmp == std::string::npos || tmp == 0U) return 0;
  const std::string rest = name.substr(tmp + 5U);  // PID.N
  const std::size_t dot = rest.find('.');
  if (dot == std::string::npos) return 0;
  long counter = 0;
  const std::string counter_text = rest.substr(dot + 1U);
  if (!(counter_text == "0" || parse_pid(counter_text, &counter))) return 0;
  return parse_pid(rest.substr(0, dot), &pid) ? pid : 0;
}

// A process with this id exists (on this machine's process table).
bool process_exists(long pid) {
  if (pid == static_cast<long>(::getpid())) return true;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

// The plain names in `dir` (no "." or ".."). False (with `error`) iff it cannot be listed.
bool list_dir(const std::string& dir, std::vector<std::string>* names, std::string* error) {
  names->clear();
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) {
    set_error(error, "cannot list directory", dir, errno);
    return false;
  }
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name != "." && name != "..") names->push_back(name);
  }
  ::closedir(d);
  std::sort(names->begin(), names->end());
  return true;
}

// Removes a staging folder and the plain files in it (it holds nothing else).
bool remove_staging(const std::string& path, std::string* error) {
  std::vector<std::string> names;
  if (!list_dir(path, &names, error)) return false;
  for (const std::string& n : names) {
    const std::string p = path + "/" + n;
    if (::unlink(p.c_str()) != 0 && errno != ENOENT) {
      set_error(error, "cannot remove", p, errno);
      return false;
    }
  }
  if (::rmdir(path.c_str()) != 0 && errno != ENOENT) {
    set_error(error, "cannot remove directory", path, errno);
    return false;
  }
  return true;
}

}  // namespace

bool file_crc32(const std::string& path, unsigned long long* bytes, unsigned long* crc, std::string* error) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    set_error(error, "cannot open", path, errno);
    return false;
  }
  uLong c = ::crc32(0L, Z_NULL, 0);
  unsigned long long n = 0U;
  unsigned char buf[1U << 16];
  std::size_t got = 0U;
  while ((got = std::fread(buf, 1, sizeof buf, f)) > 0U) {
    c = ::crc32(c, buf, static_cast<uInt>(got));
    n += got;
  }
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) {
    set_error(error, "cannot read", path, EIO);
    return false;
  }
  *bytes = n;
  *crc = static_cast<unsigned long>(c);
  return true;
}

bool read_manifest(const std::string& dir, std::vector<ManifestEntry>* entries, std::string* error) {
  entries->clear();
  const std::string path = dir + "/" + OutputSet::kManifestName;
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    if (errno == ENOENT) return true;
    set_error(error, "cannot open", path, errno);
    return false;
  }
  char line[4096];
  int line_no = 0;
  bool ok = true;
  while (ok && std::fgets(line, sizeof line, f) != nullptr) {
    ++line_no;
    std::string text(line);
    if (text.empty() || text.back() != '\n') {
      if (error != nullptr) *error = path + ":" + std::to_string(line_no) + ": line too long or not terminated";
      ok = false;
      break;
    }
    text.pop_back();
    if (text.empty() || text[0] == '#') continue;
    ManifestEntry e;
    char* end = nullptr;
    errno = 0;
    e.bytes = std::strtoull(text.c_str(), &end, 10);
    const char* p = end;
    bool good = errno == 0 && p != text.c_str() && *p == ' ';
    if (good) {
      const char* hex = p + 1;
      e.crc32 = std::strtoul(hex, &end, 16);
      good = end == hex + 8 && *end == ' ';
    }
    if (good) {
      e.name = std::string(end + 1);
      good = !e.name.empty() && e.name.find('/') == std::string::npos && e.name != "." && e.name != "..";
    }
    if (!good) {
      if (error != nullptr) *error = path + ":" + std::to_string(line_no) + ": expected 'BYTES CRC32 NAME'";
      ok = false;
      break;
    }
    entries->push_back(e);
  }
  if (ok && std::ferror(f) != 0) {
    set_error(error, "cannot read", path, EIO);
    ok = false;
  }
  std::fclose(f);
  if (!ok) entries->clear();
  return ok;
}

OutputSet::~OutputSet() {
  if (!staging_.empty()) (void)remove_staging(staging_, nullptr);
}

bool OutputSet::begin(const std::string& dir, std::string* error) {
  if (!staging_.empty()) {
    if (error != nullptr) *error = "output set for '" + dir_ + "' already begun";
    return false;
  }
  if (!make_directories(dir, error)) return false;
  std::vector<std::string> names;
  if (!list_dir(dir, &names, error)) return false;
  stale_removed_ = 0U;
  for (const std::string& n : names) {
    const long pid = owner_pid(n);
    if (pid == 0 || process_exists(pid)) continue;
    const std::string p = dir + "/" + n;
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) continue;
    if (S_ISDIR(st.st_mode) && n.rfind(kStagingPrefix, 0) == 0) {
      if (!remove_staging(p, error)) return false;
    } else if (S_ISREG(st.st_mode)) {
      if (::unlink(p.c_str()) != 0 && errno != ENOENT) {
        set_error(error, "cannot remove stale temporary", p, errno);
        return false;
      }
    } else {
      continue;
    }
    ++stale_removed_;
  }
  const std::string staging = dir + "/" + kStagingPrefix + std::to_string(static_cast<long>(::getpid()));
  if (::mkdir(staging.c_str(), 0755) != 0) {
    const int err = errno;
    if (err != EEXIST || !remove_staging(staging, nullptr) || ::mkdir(staging.c_str(), 0755) != 0) {
      set_error(error, "cannot write in output directory", dir, err);
      return false;
    }
  }
  dir_ = dir;
  staging_ = staging;
  return true;
}

bool OutputSet::commit(std::string* error) {
  if (staging_.empty()) {
    if (error != nullptr) *error = "no output set begun";
    return false;
  }
  std::vector<std::string> staged;
  if (!list_dir(staging_, &staged, error)) return false;
  // Staged files that are finished (not an AtomicOutputFile temporary still open).
  staged.erase(std::remove_if(staged.begin(), staged.end(), [](const std::string& n) { return owner_pid(n) != 0; }),
               staged.end());
  std::string manifest = "# sdpslam output set: the files below are one run's complete set; other files of\n"
                         "# this folder are not part of it. BYTES CRC32 NAME\n";
  for (const std::string& n : staged) {
    unsigned long long bytes = 0U;
    unsigned long crc = 0U;
    if (!file_crc32(staging_ + "/" + n, &bytes, &crc, error)) return false;
    char head[48];
    std::snprintf(head, sizeof head, "%llu %08lx ", bytes, crc);
    manifest += head + n + "\n";
  }
  std::vector<ManifestEntry> previous;
  std::string why;
  if (!read_manifest(dir_, &previous, &why)) previous.clear();  // unreadable: nothing is removed by it
  const std::string manifest_path = dir_ + "/" + kManifestName;
  if (::unlink(manifest_path.c_str()) != 0 && errno != ENOENT) {
    set_error(error, "cannot remove", manifest_path, errno);
    return false;
  }
  if (!fsync_directory(dir_, error)) return false;
  for (const std::string& n : staged) {
    const std::string from = staging_ + "/" + n;
    const std::string to = dir_ + "/" + n;
    if (::rename(from.c_str(), to.c_str()) != 0) {
      set_error(error, "cannot move output into place", to, errno);
      return false;
    }
  }
  for (const ManifestEntry& e : previous) {
    if (std::find(staged.begin(), staged.end(), e.name) != staged.end() || e.name == kManifestName) continue;
    const std::string p = dir_ + "/" + e.name;
    if (::unlink(p.c_str()) != 0 && errno != ENOENT) {
      set_error(error, "cannot remove previous output", p, errno);
      return false;
    }
  }
  if (!fsync_directory(dir_, error)) return false;
  return write_file_atomic(manifest_path, manifest, error);
}

}  // namespace sdpslam::io
