#pragma once
// The files one run writes into its output folder, delivered as one set.
//
// Each file is atomic on its own (atomic_file.h); a set of them is not: a run that fails
// half way (a full disk) would leave its new trajectory beside the previous run's map.
// OutputSet stages every file in a private folder inside the output folder and delivers
// them together:
//   begin()   makes the output folder, removes what an interrupted run left there (its
//             staging folder, `.NAME.tmp.PID.N` temporaries of a process that no longer
//             exists), and creates this run's staging folder `.sdpslam-staging.PID` -
//             so an output folder that cannot be written fails before any work;
//   path()    where a file of the set is written (inside the staging folder);
//   commit()  removes the manifest, moves the staged files into the output folder,
//             removes the files the previous manifest listed that this set does not
//             have, and writes the new manifest last, atomically.
// `manifest.txt` lists each file of the set with its size and CRC-32: while it exists,
// the files it lists are one run's complete set; while a commit runs it is absent. A
// failure before commit() leaves the previous set untouched. Files of the folder that
// no manifest ever listed are never touched.
//
// A set may be committed again (a long-running program writes its outputs periodically).
#include <cstddef>
#include <string>
#include <vector>

namespace sdpslam::io {

class OutputSet {
 public:
  static constexpr const char* kManifestName = "manifest.txt";

  OutputSet() = default;
  ~OutputSet();  // removes the staging folder and whatever is still staged
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;

  // False (with `error` naming the path and the cause) iff the folder cannot be made or
  // written.
  bool begin(const std::string& dir, std::string* error);
  // Where `name` (a plain file name) is staged.
  std::string path(const std::string& name) const { return staging_ + "/" + name; }
  const std::string& dir() const { return dir_; }
  const std::string& staging_dir() const { return staging_; }
  // Temporaries and staging folders of interrupted runs removed by begin().
  std::size_t stale_removed() const { return stale_removed_; }

  // Delivers every staged file. False (with `error`) iff a step failed; the manifest is
  // then absent, so a reader sees no complete set rather than a mixed one.
  bool commit(std::string* error);

 private:
  std::string dir_;
  std::string staging_;
  std::size_t stale_removed_ = 0U;
};

// One line of a manifest: `BYTES CRC32 NAME` (CRC-32 as zlib and PNG compute it, eight
// hex digits).
struct ManifestEntry {
  std::string name;
  unsigned long long bytes = 0U;
  unsigned long crc32 = 0U;
};

// The entries of `dir`'s manifest, in its order; empty when it does not exist. False
// (with `error` naming file:line) iff it exists and cannot be read or is malformed.
bool read_manifest(const std::string& dir, std::vector<ManifestEntry>* entries, std::string* error);

// Size and CRC-32 of a file. False (with `error`) iff it cannot be read.
bool file_crc32(const std::string& path, unsigned long long* bytes, unsigned long* crc, std::string* error);

}  // namespace sdpslam::io
