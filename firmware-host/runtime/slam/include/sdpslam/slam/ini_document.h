#pragma once
// A whole INI file, read once: every `key = value` with its section and line, and every
// section header with its line. The readers of `sdpslam run` ([filter] ... [log], [sdp])
// read a document, apply its keys through the options' tables (option_text.h) and only
// then validate the options, once (apply_ini_document): a file's meaning does not depend
// on the order of its keys, and a refusal still names a line to change.
//
// A line refused as read (problem(), "file:LINE: reason"): a malformed line, a line too
// long or holding a control byte (read_ini_line), a section or a key given twice
// (IniDuplicates). It counts as the file's problem at its line: an entry refused before
// it is reported first (apply_ini_document).
#include <cstdio>
#include <string>
#include <vector>

#include "sdpslam/core/option_table.h"
#include "sdpslam/slam/option_text.h"

namespace sdpslam::slam {

struct IniEntry {
  std::string section;
  std::string key;
  std::string value;
  int line = 0;
};

class IniDocument {
 public:
  // Reads `stream` to its end (not closed); `name` stands for the file in messages.
  // False only when it cannot be read; a line refused is the document's problem(), and
  // the entries stop before it.
  bool read(std::FILE* stream, const std::string& name, std::string* error);
  // Opens `path` (open_config_file) and reads it.
  bool load(const std::string& path, std::string* error);
  // The first refused line, "name:LINE: reason" (empty: none), and its line (0: none).
  const std::string& problem() const { return problem_; }
  int problem_line() const { return problem_line_; }

  const std::string& name() const { return name_; }
  const std::vector<IniEntry>& entries() const { return entries_; }
  // Section headers in file order, with their lines.
  const std::vector<std::pair<std::string, int>>& sections() const { return sections_; }
  bool has_section(const std::string& section) const;
  // The line that sets section.key (0: none).
  int line_of(const std::string& section, const std::string& key) const;
  // "name:LINE: " + why when `why` is "section.key: ..." for a key this file sets, else why.
  std::string locate(const std::string& why) const;
  // "name:LINE: " + why.
  std::string at(int line, const std::string& why) const { return name_ + ":" + std::to_string(line) + ": " + why; }

 private:
  std::string name_;
  std::vector<IniEntry> entries_;
  std::vector<std::pair<std::string, int>> sections_;
  std::string problem_;
  int problem_line_ = 0;
};

enum class EntryResult { kApplied, kSkipped, kRefused };

// Applies the entries of `doc` in file order through `apply` (EntryResult(const IniEntry&,
// Options*, std::string* why): a key's own syntax and range), then checks the options as
// a whole once with `valid` (bool(const Options&, char* why, std::size_t n)): a file
// means what its keys say whatever their order. On success *options gets the result.
// A refused entry is named at its line. Options refused as a whole are named at the
// line from which they stayed invalid to the end of the file (the entries before it left
// them valid), with the reason they had there: the first lines of a file up to that line
// are refused the same way, those before it accepted.
template <class Options, class Apply, class Valid>
bool apply_ini_document(const IniDocument& doc, Options* options, Apply apply, Valid valid, std::string* error) {
  Options trial = *options;
  std::string why;
  for (const IniEntry& e : doc.entries()) {
    if (apply(e, &trial, &why) != EntryResult::kRefused) continue;
    *error = doc.at(e.line, why);
    return false;
  }
  if (doc.problem_line() != 0) {
    *error = doc.problem();
    return false;
  }
  char reason[240];
  if (valid(trial, reason, sizeof reason)) {
    *options = trial;
    return true;
  }
  trial = *options;
  int blame = 0;
  std::string blame_why = reason;
  for (const IniEntry& e : doc.entries()) {
    if (apply(e, &trial, &why) != EntryResult::kApplied) continue;
    if (valid(trial, reason, sizeof reason)) {
      blame = 0;
    } else if (blame == 0) {
      blame = e.line;
      blame_why = reason;
    }
  }
  *error = blame != 0 ? doc.at(blame, blame_why) : doc.name() + ": " + blame_why;
  return false;
}

// apply_ini_document over the rows of `table` (entries of other sections are skipped; an
// unknown key in a section of the table is refused) and Options::validate.
template <class Options>
bool apply_ini_table(const IniDocument& doc, const OptionTable<Options>& table, Options* options,
                     std::string* error) {
  auto apply = [&table](const IniEntry& e, Options* o, std::string* why) {
    if (!table.has_section(e.section.c_str())) return EntryResult::kSkipped;
    const OptionSpec<Options>* row = table.find(e.section.c_str(), e.key.c_str());
    if (row == nullptr) {
      *why = "unknown key '" + e.key + "' in section [" + e.section + "]";
      return EntryResult::kRefused;
    }
    return set_option_text(*row, o, e.value.c_str(), why) ? EntryResult::kApplied : EntryResult::kRefused;
  };
  auto valid = [](const Options& o, char* why, std::size_t n) { return o.validate(why, n); };
  return apply_ini_document(doc, options, apply, valid, error);
}

}  // namespace sdpslam::slam
