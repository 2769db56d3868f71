#pragma once
// What an offline run over a log reports beside its outputs (the CLI prints it): the
// scans read and processed, the log's skipped lines and the repairs made to its
// odometry, and the wall time. run_sdp.h extends it with the top level's figures.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "sdpslam/io/log_reader.h"

namespace sdpslam::slam {

struct RunSummary {
  std::uint64_t scans = 0U;
  std::uint64_t processed = 0U;
  std::size_t log_error_count = 0U;
  std::vector<io::LogError> log_errors;  // the first skipped lines (io::LogReader::errors())
  std::size_t odometry_reversals_repaired = 0U;  // io::LogReader::odometry_reversals_repaired()
  std::size_t odometry_jumps_removed = 0U;       // io::LogReader::odometry_jumps_removed()
  std::size_t scans_stamped_backwards = 0U;      // io::LogReader::scans_stamped_backwards()
  std::string first_backwards_at;                // "file:line" of the first of them
  double wall_time_s = 0.0;
};

// The summary of a run that read `log_path` through `reader` to its end.
RunSummary run_summary(const io::LogReader& reader, const std::string& log_path, std::uint64_t scans,
                       std::uint64_t processed, double wall_time_s);

}  // namespace sdpslam::slam
