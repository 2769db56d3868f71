#include "sdpslam/slam/config_ini.h"

#include <ini.h>

#include <sys/stat.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

namespace sdpslam::slam {
namespace {

struct ParseState {
  SlamConfig* config;
  std::string file;
  std::string error;      // the first problem found here, "file:line: reason"
  int error_line = 0;     // its line
  std::FILE* stream = nullptr;
  int line = 0;  // lines handed to inih so far = the line being handled
  IniDuplicates duplicates;

  void fail(const std::string& why) {
    if (!error.empty()) return;
    error = file + ":" + std::to_string(line) + ": " + why;
    error_line = line;
  }
};

// The packaged inih is built without INI_HANDLER_LINENO, so lines are counted here.
char* read_line(char* str, int num, void* user) {
  auto* st = static_cast<ParseState*>(user);
  std::string why;
  char* r = read_ini_line(st->stream, str, num, &why);
  if (r == nullptr) return r;
  ++st->line;
  if (why.empty()) (void)st->duplicates.line(r, &why);
  if (!why.empty()) st->fail(why);
  return r;
}

bool parse_real(const char* text, double* out) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (end == text || *end != '\0' || errno == ERANGE || !std::isfinite(v)) return false;
  *out = v;
  return true;
}

bool parse_u32(const char* text, std::uint32_t* out) {
  if (*text == '-' || *text == '+') return false;
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (end == text || *end != '\0' || errno == ERANGE || v > 0xFFFFFFFFULL) return false;
  *out = static_cast<std::uint32_t>(v);
  return true;
}

// Nested options are addressed through small setters (member pointers cannot reach into
// DpSlamOptions::motion / ::beam directly).
bool set_option(DpSlamOptions& o, const std::string& section, const std::string& name, const char* value,
                std::string* why) {
  double r = 0.0;
  std::uint32_t u = 0U;
  auto real = [&](double& field) {
    if (!parse_real(value, &r)) {
      *why = "'" + std::string(value) + "' is not a finite number";
      return false;
    }
    field = r;
    return true;
  };
  auto u32 = [&](std::uint32_t& field) {
    if (!parse_u32(value, &u)) {
      *why = "'" + std::string(value) + "' is not a non-negative 32-bit integer";
      return false;
    }
    field = u;
    return true;
  };
  if (section == "filter") {
    if (name == "particles") return u32(o.particle_count);
    if (name == "resample_neff_ratio") return real(o.resample_neff_ratio);
    if (name == "update_min_travel_m") return real(o.update_min_travel_m);
    if (name == "update_min_rotation_rad") return real(o.update_min_rotation_rad);
  } else if (section == "motion") {
    if (name == "alpha_rot_from_rot") return real(o.motion.alpha_rot_from_rot);
    if (name == "alpha_rot_from_trans") return real(o.motion.alpha_rot_from_trans);
    if (name == "alpha_trans_from_trans") return real(o.motion.alpha_trans_from_trans);
    if (name == "alpha_trans_from_rot") return real(o.motion.alpha_trans_from_rot);
    if (name == "min_sigma_trans_m") return real(o.motion.min_sigma_trans_m);
    if (name == "min_sigma_rot_rad") return real(o.motion.min_sigma_rot_rad);
  } else if (section == "observation") {
    if (name == "sigma_hit_m") return real(o.beam.sigma_hit_m);
    if (name == "window_m") return real(o.beam.window_m);
    if (name == "prior_hits") return real(o.beam.prior_hits);
    if (name == "prior_misses") return real(o.beam.prior_misses);
    if (name == "unknown_stop_probability") return real(o.beam.unknown_stop_probability);
    if (name == "floor_likelihood") return real(o.beam.floor_likelihood);
    if (name == "weight_beam_stride") return u32(o.beam.weight_beam_stride);
    if (name == "max_update_range_m") return real(o.beam.max_update_range_m);
    if (name == "no_return_free_m") return real(o.beam.no_return_free_m);
    if (name == "likelihood_temperature") return real(o.beam.likelihood_temperature);
  } else if (section == "proposal") {
    if (name == "kind") {
      if (std::strcmp(value, "odometry") == 0) {
        o.proposal = DpSlamOptions::Proposal::kOdometry;
      } else if (std::strcmp(value, "scan_match") == 0) {
        o.proposal = DpSlamOptions::Proposal::kScanMatch;
      } else {
        *why = "'" + std::string(value) + "' is not odometry or scan_match";
        return false;
      }
      return true;
    }
    if (name == "weight") {
      if (std::strcmp(value, "match") == 0) {
        o.proposal_weight = DpSlamOptions::ProposalWeight::kMatch;
      } else if (std::strcmp(value, "neighbourhood") == 0) {
        o.proposal_weight = DpSlamOptions::ProposalWeight::kNeighbourhood;
      } else {
        *why = "'" + std::string(value) + "' is not match or neighbourhood";
        return false;
      }
      return true;
    }
    if (name == "linear_step_m") return real(o.match.linear_step_m);
    if (name == "angular_step_rad") return real(o.match.angular_step_rad);
    if (name == "refinements") return u32(o.match.refinements);
    if (name == "max_iterations") return u32(o.match.max_iterations);
    if (name == "beam_stride") return u32(o.match.beam_stride);
    if (name == "min_beams") return u32(o.match.min_beams);
    if (name == "min_known_fraction") return real(o.match.min_known_fraction);
    if (name == "min_mean_log_likelihood") return real(o.match.min_mean_log_likelihood);
    if (name == "sample_sigma_xy_m") return real(o.proposal_sigma_xy_m);
    if (name == "sample_sigma_rot_rad") return real(o.proposal_sigma_rot_rad);
  } else if (section == "map") {
    if (name == "resolution_m") return real(o.map_resolution_m);
    if (name == "width_m") return real(o.map_width_m);
    if (name == "height_m") return real(o.map_height_m);
    if (name == "tile_capacity") return u32(o.map_tile_capacity);
    if (name == "observations_base") return u32(o.map_observations_base);
    if (name == "observations_per_particle") return u32(o.map_observations_per_particle);
  } else if (section == "capacity") {
    if (name == "ancestry_nodes_per_particle") return u32(o.ancestry_nodes_per_particle);
    if (name == "path_entries_per_particle") return u32(o.path_entries_per_particle);
  }
  *why = "unknown key '" + name + "' in section [" + section + "]";
  return false;
}

int handler(void* user, const char* section, const char* name, const char* value) {
  auto* st = static_cast<ParseState*>(user);
  if (name == nullptr) return 1;  // section header alone
  if (!st->error.empty()) return 0;
  std::string dup;
  if (!st->duplicates.key(section, name, &dup)) {
    st->fail(dup);
    return 0;
  }
  // [sdp] belongs to the SDP-SLAM top level; its keys are read by load_sdp_ini (run_sdp.h).
  if (std::strcmp(section, "sdp") == 0) return 1;
  std::string why;
  const ConfigKeyResult r = apply_config_key(st->config, section, name, value, &why);
  if (r == ConfigKeyResult::kApplied) return 1;
  if (r == ConfigKeyResult::kUnknown) why = "unknown key '" + std::string(name) + "' in section [" + section + "]";
  st->fail(why);
  return 0;
}

}  // namespace

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

bool IniDuplicates::line(const char* line, std::string* why) {
  const char* p = line;
  while (*p == ' ' || *p == '\t') ++p;
  if (*p != '[') return true;
  const char* end = std::strchr(p, ']');
  if (end == nullptr) return true;  // malformed: inih reports it
  std::string sec(p + 1, end);
  while (!sec.empty() && (sec.back() == ' ' || sec.back() == '\t')) sec.pop_back();
  while (!sec.empty() && (sec.front() == ' ' || sec.front() == '\t')) sec.erase(0, 1);
  if (sections_.insert(sec).second) return true;
  *why = "section [" + sec + "] given twice (merge its keys into the first)";
  return false;
}

bool IniDuplicates::key(const char* section, const char* name, std::string* why) {
  if (keys_.insert({section, name}).second) return true;
  *why = "key '" + std::string(name) + "' given twice in section [" + section + "]";
  return false;
}

bool is_slam_config_section(const std::string& section) {
  return section == "filter" || section == "motion" || section == "observation" || section == "proposal" ||
         section == "map" || section == "capacity" || section == "log";
}

ConfigKeyResult apply_config_key(SlamConfig* config, const std::string& sec, const std::string& key,
                                 const char* value, std::string* why) {
  if (!is_slam_config_section(sec)) return ConfigKeyResult::kUnknown;
  if (sec == "log") {
    if (key == "max_speed_mps" || key == "max_turn_rate_radps") {
      double v = 0.0;
      if (parse_real(value, &v) && v >= 0.0 && v <= 1000.0) {
        (key == "max_speed_mps" ? config->log.max_speed_mps : config->log.max_turn_rate_radps) = v;
        return ConfigKeyResult::kApplied;
      }
      *why = "log." + key + ": '" + std::string(value) + "' out of range [0, 1000] (0 = not checked)";
      return ConfigKeyResult::kInvalid;
    }
    if (key != "default_range_max_m") return ConfigKeyResult::kUnknown;
    double r = 0.0;
    if (parse_real(value, &r) && r > 0.0 && r <= 1000.0) {
      config->log.default_range_max_m = static_cast<float>(r);
      return ConfigKeyResult::kApplied;
    }
    *why = "log.default_range_max_m: '" + std::string(value) + "' out of range (0, 1000]";
    return ConfigKeyResult::kInvalid;
  }
  DpSlamOptions trial = config->filter;
  std::string reason_text;
  if (!set_option(trial, sec, key, value, &reason_text)) {
    if (reason_text.rfind("unknown key", 0) == 0) return ConfigKeyResult::kUnknown;
    *why = reason_text;
    return ConfigKeyResult::kInvalid;
  }
  char reason[200];
  if (!trial.validate(reason, sizeof reason)) {
    *why = reason;
    return ConfigKeyResult::kInvalid;
  }
  config->filter = trial;
  return ConfigKeyResult::kApplied;
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

namespace {

// The line that sets [section] key, found by inih as every reader here parses (0: none).
struct KeyLine {
  std::FILE* stream = nullptr;
  std::string section;
  std::string key;
  int line = 0;
  int found = 0;
};

char* key_line_read(char* str, int num, void* user) {
  auto* k = static_cast<KeyLine*>(user);
  std::string ignored;
  char* r = read_ini_line(k->stream, str, num, &ignored);
  if (r != nullptr) ++k->line;
  return r;
}

int key_line_handler(void* user, const char* section, const char* name, const char*) {
  auto* k = static_cast<KeyLine*>(user);
  if (k->found == 0 && name != nullptr && k->section == section && k->key == name) k->found = k->line;
  return 1;
}

}  // namespace

std::string locate_option_error(const std::string& path, const std::string& why) {
  const std::size_t dot = why.find('.');
  const std::size_t colon = why.find(':');
  if (path.empty() || dot == std::string::npos || colon == std::string::npos || dot > colon) return why;
  std::size_t end = dot + 1U;
  while (end < colon && (std::isalnum(static_cast<unsigned char>(why[end])) != 0 || why[end] == '_')) ++end;
  KeyLine k;
  k.section = why.substr(0, dot);
  k.key = why.substr(dot + 1U, end - dot - 1U);
  if (k.key.empty()) return why;
  std::string ignored;
  k.stream = open_config_file(path, &ignored);
  if (k.stream == nullptr) return why;
  (void)ini_parse_stream(key_line_read, &k, key_line_handler, &k);
  std::fclose(k.stream);
  return k.found == 0 ? why : path + ":" + std::to_string(k.found) + ": " + why;
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
  ParseState st{config, name, {}, 0, stream, 0, {}};
  const int rc = ini_parse_stream(read_line, &st, handler, &st);
  // inih's rc is the first line it could not parse or whose handler failed; a handler
  // failure has its reason here, so an earlier rc is a malformed line.
  std::string why;
  if (rc > 0 && (st.error.empty() || rc < st.error_line)) {
    why = name + ":" + std::to_string(rc) + ": malformed line (expected [section] or key = value)";
  } else if (!st.error.empty()) {
    why = st.error;
  } else if (rc != 0 || std::ferror(stream) != 0) {
    why = name + ": read error";
  }
  if (why.empty()) return true;
  if (error != nullptr) *error = why;
  return false;
}

}  // namespace sdpslam::slam
