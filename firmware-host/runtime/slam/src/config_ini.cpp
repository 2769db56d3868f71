#include "sdpslam/slam/config_ini.h"

#include "sdpslam/slam/ini_document.h"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>

namespace sdpslam::slam {
char* read_ini_line(std::FILE* stream, char* str, int num, std::string* why) {
  const auto room = static_cast<std::size_t>(num) - 1U;  // bytes before the terminating NUL
  std::size_t len = 0;
  bool too_long = false;
  int control = -1;  // the first control byte other than tab, CR and LF
  int c = EOF;
  while ((c = std::getc(stream)) != EOF) {
    if (len < room) {
      str[len++] = static_cast<char>(c);
    } else {
      too_long = true;
    }
    if (control < 0 && (c < 0x20 || c == 0x7F) && c != '\t' && c != '\r' && c != '\n') control = c;
    if (c == '\n') break;
  }
  if (len == 0 && !too_long && c == EOF) return nullptr;
  str[len] = '\0';
  // A control byte means a binary file (or a terminal escape sequence): the line is
  // refused whole, so no error message echoes its bytes to the user's terminal.
  if (too_long || control >= 0) {
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02X", static_cast<unsigned>(control));
    *why = too_long ? "line longer than " + std::to_string(num - 2) + " characters"
                    : std::string("control byte ") + hex + " in the line (not a text file?)";
    str[0] = '\n';
    str[1] = '\0';
  }
  return str;
}

bool ini_section_header(const char* line, std::string* section) {
  const char* p = line;
  while (*p == ' ' || *p == '\t') ++p;
  if (*p != '[') return false;
  const char* end = std::strchr(p, ']');
  if (end == nullptr) return false;
  std::string sec(p + 1, end);
  while (!sec.empty() && (sec.back() == ' ' || sec.back() == '\t')) sec.pop_back();
  while (!sec.empty() && (sec.front() == ' ' || sec.front() == '\t')) sec.erase(0, 1);
  *section = sec;
  return true;
}

bool IniDuplicates::section(const std::string& sec, std::string* why) {
  if (sections_.insert(sec).second) return true;
  *why = "section [" + sec + "] given twice (merge its keys into the first)";
  return false;
}

bool IniDuplicates::key(const char* section, const char* name, std::string* why) {
  if (keys_.insert({section, name}).second) return true;
  *why = "key '" + std::string(name) + "' given twice in section [" + section + "]";
  return false;
}

namespace {

const OptionSpec<io::LogReaderOptions> kLogRows[] = {
    SDPSLAM_OPTION_F32(io::LogReaderOptions, "log", "default_range_max_m", default_range_max_m, 0.0, 1000.0, true, "m",
                       "readings at or above this are no return when the log has no maximum"),
    SDPSLAM_OPTION_REAL(io::LogReaderOptions, "log", "max_speed_mps", max_speed_mps, 0.0, 1000.0, "m/s",
                        "odometry faster than this (+0.5 m) is a reset or corruption, not applied (0 = not checked)"),
    SDPSLAM_OPTION_REAL(io::LogReaderOptions, "log", "max_turn_rate_radps", max_turn_rate_radps, 0.0, 1000.0,
                        "rad/s", "... turning faster (+0.5 rad) (0 = not checked)"),
};

}  // namespace

OptionTable<io::LogReaderOptions> log_option_table() { return {kLogRows, sizeof kLogRows / sizeof kLogRows[0]}; }

bool is_slam_config_section(const std::string& section) {
  return section == "filter" || section == "motion" || section == "observation" || section == "proposal" ||
         section == "map" || section == "capacity" || section == "log";
}

ConfigKeyResult apply_config_key(SlamConfig* config, const std::string& sec, const std::string& key,
                                 const char* value, std::string* why) {
  if (!is_slam_config_section(sec)) return ConfigKeyResult::kUnknown;
  if (sec == "log") {
    const OptionSpec<io::LogReaderOptions>* row = log_option_table().find("log", key.c_str());
    if (row == nullptr) return ConfigKeyResult::kUnknown;
    return set_option_text(*row, &config->log, value, why) ? ConfigKeyResult::kApplied : ConfigKeyResult::kInvalid;
  }
  const OptionSpec<DpSlamOptions>* row = DpSlamOptions::table().find(sec.c_str(), key.c_str());
  if (row == nullptr) return ConfigKeyResult::kUnknown;
  return set_option_text(*row, &config->filter, value, why) ? ConfigKeyResult::kApplied : ConfigKeyResult::kInvalid;
}

std::FILE* open_config_file(const std::string& path, std::string* error) {
  std::FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) {
    *error = path + ": cannot open: " + std::strerror(errno);
    return nullptr;
  }
  struct stat st {};
  if (::fstat(::fileno(f), &st) != 0) {
    *error = path + ": cannot open: " + std::strerror(errno);
    std::fclose(f);
    return nullptr;
  }
  if (S_ISDIR(st.st_mode)) {
    *error = path + ": is a directory, not a configuration file";
    std::fclose(f);
    return nullptr;
  }
  return f;
}

std::string locate_option_error(const std::string& path, const std::string& why) {
  if (path.empty()) return why;
  IniDocument doc;
  std::string ignored;
  if (!doc.load(path, &ignored)) return why;
  return doc.locate(why);
}

bool load_config_ini(const std::string& path, SlamConfig* config, std::string* error) {
  std::string why;
  std::FILE* f = open_config_file(path, &why);
  if (f == nullptr) {
    if (error != nullptr) *error = why;
    return false;
  }
  const bool ok = load_config_ini(f, path, config, error);
  std::fclose(f);
  return ok;
}

bool load_config_ini(std::FILE* stream, const std::string& name, SlamConfig* config, std::string* error) {
  IniDocument doc;
  std::string why;
  if (!doc.read(stream, name, &why)) {
    if (error != nullptr) *error = why;
    return false;
  }
  // [sdp] is the top level's (load_sdp_ini).
  auto apply = [](const IniEntry& e, SlamConfig* c, std::string* reason) {
    if (e.section == "sdp") return EntryResult::kSkipped;
    const ConfigKeyResult r = apply_config_key(c, e.section, e.key, e.value.c_str(), reason);
    if (r == ConfigKeyResult::kApplied) return EntryResult::kApplied;
    if (r == ConfigKeyResult::kUnknown) *reason = "unknown key '" + e.key + "' in section [" + e.section + "]";
    return EntryResult::kRefused;
  };
  auto valid = [](const SlamConfig& c, char* reason, std::size_t n) { return c.filter.validate(reason, n); };
  if (apply_ini_document(doc, config, apply, valid, &why)) return true;
  if (error != nullptr) *error = why;
  return false;
}

}  // namespace sdpslam::slam
