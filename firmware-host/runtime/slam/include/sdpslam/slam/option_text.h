#pragma once
// Option values as text, for every INI reader and `--print-config`: one dialect, read and
// written through the options' tables (core option_table.h). Numbers are C-locale
// decimal (u32 without a sign); booleans are true/false, yes/no, on/off or 1/0; a choice
// is one of its row's names. Leading and trailing blanks are not part of a value (inih
// strips them).
#include <cstdint>
#include <string>

#include "sdpslam/core/option_table.h"

namespace sdpslam::slam {

bool parse_real_text(const char* text, double* out);
bool parse_u32_text(const char* text, std::uint32_t* out);
bool parse_bool_text(const char* text, bool* out);
// The shortest decimal text that reads back as exactly `v`.
std::string real_text(double v);

// Sets the row's field from `text`. False, with *why = "section.key: reason" and the
// field unchanged, iff the text is not a value of the row's kind or is outside the
// row's own range (checks that join fields are the struct's validate(), run once the
// whole file is read).
template <class Options>
bool set_option_text(const OptionSpec<Options>& spec, Options* options, const char* text, std::string* why) {
  const std::string name = std::string(spec.section) + "." + spec.key + ": ";
  Options trial = *options;
  bool parsed = false;
  const char* expected = "";
  switch (spec.kind) {
    case OptionKind::kReal:
      parsed = parse_real_text(text, &option_field<double>(spec, trial));
      expected = "a finite number";
      break;
    case OptionKind::kF32: {
      double d = 0.0;
      parsed = parse_real_text(text, &d) && d >= -3.4e38 && d <= 3.4e38;
      if (parsed) option_field<float>(spec, trial) = static_cast<float>(d);
      expected = "a finite number";
      break;
    }
    case OptionKind::kU32:
      parsed = parse_u32_text(text, &option_field<std::uint32_t>(spec, trial));
      expected = "a non-negative 32-bit integer";
      break;
    case OptionKind::kBool:
      parsed = parse_bool_text(text, &option_field<bool>(spec, trial));
      expected = "true or false";
      break;
    case OptionKind::kChoice:
      for (std::uint8_t i = 0U; i < spec.choice_count; ++i) {
        if (std::string(text) == spec.choices[i].name) {
          option_field<std::uint8_t>(spec, trial) = spec.choices[i].value;
          parsed = true;
        }
      }
      break;
  }
  if (!parsed) {
    if (spec.kind == OptionKind::kChoice) {
      std::string names;
      for (std::uint8_t i = 0U; i < spec.choice_count; ++i) {
        names += (i == 0U ? "" : i + 1U == spec.choice_count ? " or " : ", ") + std::string(spec.choices[i].name);
      }
      *why = name + "'" + text + "' is not " + names;
    } else {
      *why = name + "'" + text + "' is not " + expected;
    }
    return false;
  }
  char reason[200];
  if (!option_in_range(spec, trial, reason, sizeof reason)) {
    *why = reason;
    return false;
  }
  *options = trial;
  return true;
}

// The row's value as its INI text.
template <class Options>
std::string option_text(const OptionSpec<Options>& spec, const Options& options) {
  switch (spec.kind) {
    case OptionKind::kReal: return real_text(option_field<double>(spec, options));
    case OptionKind::kF32: return real_text(static_cast<double>(option_field<float>(spec, options)));
    case OptionKind::kU32: return std::to_string(option_field<std::uint32_t>(spec, options));
    case OptionKind::kBool: return option_field<bool>(spec, options) ? "true" : "false";
    case OptionKind::kChoice: {
      const char* n = option_choice_name(spec, options);
      return n != nullptr ? n : "?";
    }
  }
  return "?";
}

// The row's range as text: "[0, 1]", "(0, 5]", "sum | mean", "true | false".
template <class Options>
std::string option_range_text(const OptionSpec<Options>& spec) {
  switch (spec.kind) {
    case OptionKind::kBool: return "true | false";
    case OptionKind::kChoice: {
      std::string names;
      for (std::uint8_t i = 0U; i < spec.choice_count; ++i) names += (i == 0U ? "" : " | ") + std::string(spec.choices[i].name);
      return names;
    }
    case OptionKind::kU32:
      return "[" + std::to_string(static_cast<unsigned long long>(spec.min)) + ", " +
             std::to_string(static_cast<unsigned long long>(spec.max)) + "]";
    case OptionKind::kReal:
    case OptionKind::kF32: break;
  }
  return (spec.min_open ? "(" : "[") + real_text(spec.min) + ", " + real_text(spec.max) + "]";
}

// Every row of `table` as INI text, a section header before each new section: the
// effective configuration (`sdpslam run --print-config`), readable back as a file.
//   key = value   ; unit, range: doc
//
// One line of that text (also the daemon's own keys, firmware-host/daemon_config).
std::string ini_option_line(const char* key, const std::string& value, const char* unit, const std::string& range,
                            const char* doc);

template <class Options>
std::string options_ini_text(const OptionTable<Options>& table, const Options& options) {
  std::string out;
  const char* section = nullptr;
  for (const OptionSpec<Options>& row : table) {
    if (section == nullptr || std::string(section) != row.section) {
      section = row.section;
      out += (out.empty() ? "[" : "\n[") + std::string(section) + "]\n";
    }
    out += ini_option_line(row.key, option_text(row, options), row.unit, option_range_text(row), row.doc);
  }
  return out;
}

}  // namespace sdpslam::slam
