#pragma once
// INI configuration of the bottom-level filter (firmware-host/runtime/slam/default.ini documents every
// key). Sections and keys mirror DpSlamOptions; `[log] default_range_max_m` sets the
// log reader's no-return threshold for formats that do not carry one.
#include <cstdio>
#include <set>
#include <string>
#include <utility>

#include "sdpslam/core/dpslam_options.h"
#include "sdpslam/core/option_table.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::slam {

struct SlamConfig {
  DpSlamOptions filter;
  io::LogReaderOptions log;
};

// Applies the keys of `path` on top of *config (keys not in the file keep their value),
// through DpSlamOptions::table(), then validates the options once, whatever the order of
// the keys. False iff the file cannot be read (IniDocument: a malformed line, a line too
// long or holding a control byte, a section or a key given twice, [sdp] included), a
// section/key is unknown, a value is not of its key's kind or outside its range, or the
// options as a whole are invalid; `error` is then "file:line: reason" of the line to
// change, and *config is unchanged. An [sdp] section (SDP-SLAM's top level, read by
// load_sdp_ini in run_sdp.h) is skipped.
bool load_config_ini(const std::string& path, SlamConfig* config, std::string* error);
// The same from an open stream (read to its end, not closed); `name` stands for the file
// in messages.
bool load_config_ini(std::FILE* stream, const std::string& name, SlamConfig* config, std::string* error);

// Opens a configuration file for reading, for every INI reader (this file's, run_sdp.h's
// and sdpslamd's). Null, with `error` = "path: reason", iff it cannot be opened or is a
// directory (fopen accepts one on Linux, and reading it looks like an empty file: the
// built-in defaults would run unannounced). Files, pipes and /dev/null are accepted.
std::FILE* open_config_file(const std::string& path, std::string* error);

// An option refused after the file was read (a check that joins keys, or one the
// command line set) is named as "section.key: reason" (DpSlamOptions / SdpOptions
// validate, SdpSlam::check_options). Returns "path:LINE: " + why when `path` sets that
// key (LINE its line), else `why` unchanged: the user is sent to the line to change.
std::string locate_option_error(const std::string& path, const std::string& why);

// The line source of every INI reader above, for inih's ini_parse_stream (an ini_reader
// with the stream passed separately). inih reads with fgets into a buffer of `num` bytes
// and parses each piece as a line of its own, so a longer line would be cut: its first
// piece applied as a value, its rest parsed as the next line and every later line number
// shifted. Here a physical line is read whole: str gets it, '\n' included, and one longer
// than num - 2 characters (before its '\n') or holding a control byte other than tab
// and CR (a NUL would end the text inih sees; any of them means a binary file, whose
// bytes must not be echoed to a terminal in a message) is refused: `why` says so and str gets an empty line, so that inih's
// count of lines stays the file's. Returns str, or null at the end of the stream (or a
// read error: see std::ferror). num >= 2.
char* read_ini_line(std::FILE* stream, char* str, int num, std::string* why);

// True, with the section's name (blanks around it trimmed), when `line` is a section
// header "[name]" (blanks before '[' allowed); false for every other line, a header
// without its ']' included (inih refuses that line).
bool ini_section_header(const char* line, std::string* section);

// A section given twice, or a key given twice in one section, makes a file mean what its
// last occurrence says, which nobody reading the first one expects: every INI reader
// refuses both. Feed it each section header as read (the packaged inih does not hand
// headers to handlers) and each key as handled.
class IniDuplicates {
 public:
  // False, with `why`, when `section` was already opened (see ini_section_header).
  bool section(const std::string& section, std::string* why);
  // False, with `why`, when `name` was already given in `section`.
  bool key(const char* section, const char* name, std::string* why);

 private:
  std::set<std::string> sections_;
  std::set<std::pair<std::string, std::string>> keys_;
};

// One `key = value` of the sections above ([filter] [motion] [observation] [map]
// [capacity] [log]), for programs whose own INI files embed these sections (sdpslamd).
// kApplied: *config changed; kUnknown: not a key of these sections (*config untouched);
// kInvalid: a key of these sections whose value is malformed or outside the key's range
// (*config untouched, *why says why, without file:line). The checks that join keys
// (DpSlamOptions::validate) are the caller's, once every key is applied.
enum class ConfigKeyResult { kApplied, kUnknown, kInvalid };
ConfigKeyResult apply_config_key(SlamConfig* config, const std::string& section, const std::string& key,
                                 const char* value, std::string* why);
// The [log] section's keys: the log reader's options this file sets (io::LogReaderOptions).
OptionTable<io::LogReaderOptions> log_option_table();
// True iff `section` is one of the sections above.
bool is_slam_config_section(const std::string& section);

}  // namespace sdpslam::slam
