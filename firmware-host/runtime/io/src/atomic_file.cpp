// Atomic file replacement (see atomic_file.h). The recipe is the one POSIX guarantees:
// rename(2) within one file system replaces the target atomically, so the temporary is
// created in the target's own directory; fsync(2) of the file before the rename and of
// the directory after it makes the new contents and the new name durable.
#include "sdpslam/io/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>

namespace sdpslam::io {
namespace {

// Distinguishes temporaries opened by the same process (several outputs at once).
std::atomic<unsigned long> g_temp_counter{0};
std::atomic<std::uint64_t> g_fsyncs{0};

int counted_fsync(int fd) {
  g_fsyncs.fetch_add(1U, std::memory_order_relaxed);
  return ::fsync(fd);
}

void set_error(std::string* error, const std::string& what, const std::string& path, int err) {
  if (error != nullptr) *error = what + " '" + path + "': " + std::strerror(err);
}

// Directory part of `path` ("." when it has none) and the base name.
void split_path(const std::string& path, std::string* dir, std::string* base) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos) {
    *dir = ".";
    *base = path;
  } else if (slash == 0) {
    *dir = "/";
    *base = path.substr(1);
  } else {
    *dir = path.substr(0, slash);
    *base = path.substr(slash + 1);
  }
}

}  // namespace

std::uint64_t fsync_count() { return g_fsyncs.load(std::memory_order_relaxed); }

bool fsync_directory(const std::string& dir, std::string* error) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    set_error(error, "cannot open directory", dir, errno);
    return false;
  }
  bool ok = true;
  if (counted_fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
    set_error(error, "fsync failed on directory", dir, errno);
    ok = false;
  }
  ::close(fd);
  return ok;
}

AtomicOutputFile::~AtomicOutputFile() { abandon(); }

bool AtomicOutputFile::open(const std::string& path, std::string* error) {
  abandon();
  std::string dir;
  std::string base;
  split_path(path, &dir, &base);
  if (base.empty()) {
    if (error != nullptr) *error = "cannot write '" + path + "': the path names a directory";
    return false;
  }
  // `.<name>.tmp.<pid>.<counter>`: hidden, beside the target, unique per process and
  // per open; O_EXCL never reuses a file someone else left behind.
  const std::string temp = (dir == "/" ? std::string("/") : dir + "/") + "." + base + ".tmp." +
                           std::to_string(static_cast<long>(::getpid())) + "." +
                           std::to_string(g_temp_counter.fetch_add(1));
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) {
    set_error(error, "cannot create temporary file for", path, errno);
    if (error != nullptr) *error += " (temporary '" + temp + "')";
    return false;
  }
  fd_ = fd;
  write_errno_ = 0;
  cookie_io_functions_t io{};
  io.write = [](void* self, const char* data, std::size_t size) -> ssize_t {
    return static_cast<ssize_t>(write_to_fd(self, data, size));
  };
  io.close = close_fd;
  std::FILE* f = ::fopencookie(this, "wb", io);
  if (f == nullptr) {
    fd_ = -1;
    const int err = errno;
    ::close(fd);
    ::unlink(temp.c_str());
    set_error(error, "cannot open stream for", path, err);
    return false;
  }
  file_ = f;
  path_ = path;
  temp_path_ = temp;
  return true;
}

bool AtomicOutputFile::commit(std::string* error, Sync sync) {
  if (file_ == nullptr) {
    if (error != nullptr) *error = "cannot commit '" + path_ + "': no file is open";
    return false;
  }
  int err = 0;
  std::string what;
  if (std::ferror(file_) != 0) {
    err = write_errno_ != 0 ? write_errno_ : EIO;
    what = "a write failed on";
  } else if (std::fflush(file_) != 0) {
    err = write_errno_ != 0 ? write_errno_ : errno;
    what = "a write failed on";
  } else if (sync == Sync::kDurable && counted_fsync(fd_) != 0) {
    err = errno;
    what = "fsync failed on";
  }
  const int close_rc = std::fclose(file_);
  file_ = nullptr;
  if (err == 0 && close_rc != 0) {
    err = errno;
    what = "close failed on";
  }
  if (err == 0 && ::rename(temp_path_.c_str(), path_.c_str()) != 0) {
    err = errno;
    what = "cannot rename temporary over";
  }
  if (err != 0) {
    ::unlink(temp_path_.c_str());
    set_error(error, what, path_, err);
    temp_path_.clear();
    return false;
  }
  temp_path_.clear();
  if (sync == Sync::kAtomicOnly) return true;
  std::string dir;
  std::string base;
  split_path(path_, &dir, &base);
  return fsync_directory(dir, error);
}

long AtomicOutputFile::write_to_fd(void* self, const char* data, std::size_t size) {
  auto* out = static_cast<AtomicOutputFile*>(self);
  std::size_t done = 0U;
  while (done < size) {
    const ssize_t n = ::write(out->fd_, data + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      if (out->write_errno_ == 0) out->write_errno_ = n < 0 ? errno : EIO;
      errno = out->write_errno_;
      return 0;  // fopencookie: 0 is an error, stdio sets the stream's error flag
    }
    done += static_cast<std::size_t>(n);
  }
  return static_cast<long>(done);
}

int AtomicOutputFile::close_fd(void* self) {
  auto* out = static_cast<AtomicOutputFile*>(self);
  const int rc = out->fd_ >= 0 ? ::close(out->fd_) : 0;
  out->fd_ = -1;
  return rc;
}

void AtomicOutputFile::abandon() {
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;
  }
  if (!temp_path_.empty()) {
    ::unlink(temp_path_.c_str());
    temp_path_.clear();
  }
}

bool write_file_atomic(const std::string& path, const std::string& contents, std::string* error, Sync sync) {
  AtomicOutputFile out;
  if (!out.open(path, error)) return false;
  if (!contents.empty() && std::fwrite(contents.data(), 1, contents.size(), out.stream()) != contents.size()) {
    const int err = errno;
    out.abandon();
    set_error(error, "write failed on", path, err);
    return false;
  }
  return out.commit(error, sync);
}

bool make_directories(const std::string& dir, std::string* error) {
  if (dir.empty()) {
    if (error != nullptr) *error = "cannot create directory: empty path";
    return false;
  }
  // Create each prefix in turn; EEXIST is fine as long as it is a directory.
  std::size_t pos = 0;
  while (pos != std::string::npos) {
    pos = dir.find('/', pos + 1);
    const std::string prefix = dir.substr(0, pos);
    if (prefix.empty() || prefix == "/") continue;
    if (::mkdir(prefix.c_str(), 0755) != 0) {
      const int err = errno;
      struct stat st {};
      if (err == EEXIST && ::stat(prefix.c_str(), &st) == 0 && S_ISDIR(st.st_mode)) continue;
      set_error(error, "cannot create directory", prefix, err == EEXIST ? ENOTDIR : err);
      return false;
    }
  }
  return true;
}

}  // namespace sdpslam::io
