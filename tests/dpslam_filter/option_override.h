#pragma once
// Option overrides on a benchmark program's command line: section.key=value, a key of
// DpSlamOptions::table() and its value in the INI files' dialect
// (firmware-host/runtime/slam/option_text.h).
#include <cstring>
#include <string>

#include "sdpslam/core/dpslam_options.h"
#include "sdpslam/slam/option_text.h"

namespace sdpslam::test {

// One section.key=value: the row and its value as text.
struct OptionOverride {
  const OptionSpec<DpSlamOptions>* row = nullptr;
  std::string value;
};

// Sets `o`'s field from the override's text (slam::set_option_text); false, with *why,
// if the text is not a value of the row or the options are then invalid
// (DpSlamOptions::validate's reason).
inline bool apply_override(const OptionOverride& v, DpSlamOptions* o, std::string* why) {
  if (!slam::set_option_text(*v.row, o, v.value.c_str(), why)) return false;
  char reason[256] = {};
  if (o->validate(reason, sizeof reason)) return true;
  *why = reason;
  return false;
}

// Reads `arg` as section.key=value and checks it on `base` (apply_override); false, with
// *why, if it is not a key of the table or its value does not apply.
inline bool parse_override(const char* arg, const DpSlamOptions& base, OptionOverride* out, std::string* why) {
  const char* dot = std::strchr(arg, '.');
  const char* eq = std::strchr(arg, '=');
  const OptionSpec<DpSlamOptions>* row =
      dot != nullptr && eq != nullptr && dot < eq
          ? DpSlamOptions::table().find(std::string(arg, static_cast<std::size_t>(dot - arg)).c_str(),
                                        std::string(dot + 1, static_cast<std::size_t>(eq - dot - 1)).c_str())
          : nullptr;
  if (row == nullptr) {
    *why = "not section.key=value of a DpSlamOptions key";
    return false;
  }
  *out = OptionOverride{row, eq + 1};
  DpSlamOptions check = base;
  return apply_override(*out, &check, why);
}

}  // namespace sdpslam::test
