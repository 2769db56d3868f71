#include "sdpslam/slam/ini_document.h"

#include <ini.h>

#include <cctype>

#include "sdpslam/slam/config_ini.h"

namespace sdpslam::slam {
namespace {

struct ReadState {
  std::vector<IniEntry>* entries;
  std::vector<std::pair<std::string, int>>* sections;
  std::FILE* stream;
  int line = 0;        // lines handed to inih so far = the line being handled
  int error_line = 0;  // the first line refused here, with its reason
  std::string why;
  IniDuplicates duplicates;

  void fail(const std::string& reason) {
    if (error_line != 0) return;
    error_line = line;
    why = reason;
  }
};

// The packaged inih is built without INI_HANDLER_LINENO and without
// INI_CALL_HANDLER_ON_NEW_SECTION: lines are counted, and headers found, here.
char* read_line(char* str, int num, void* user) {
  auto* st = static_cast<ReadState*>(user);
  std::string why;
  char* r = read_ini_line(st->stream, str, num, &why);
  if (r == nullptr) return r;
  ++st->line;
  if (!why.empty()) {
    st->fail(why);
    return r;
  }
  std::string sec;
  if (ini_section_header(r, &sec)) {
    st->sections->push_back({sec, st->line});
    if (!st->duplicates.section(sec, &why)) st->fail(why);
  }
  return r;
}

int handler(void* user, const char* section, const char* name, const char* value) {
  auto* st = static_cast<ReadState*>(user);
  if (name == nullptr) return 1;
  if (st->error_line != 0) return 0;
  std::string why;
  if (!st->duplicates.key(section, name, &why)) {
    st->fail(why);
    return 0;
  }
  st->entries->push_back(IniEntry{section, name, value, st->line});
  return 1;
}

}  // namespace

bool IniDocument::read(std::FILE* stream, const std::string& name, std::string* error) {
  name_ = name;
  entries_.clear();
  sections_.clear();
  problem_.clear();
  problem_line_ = 0;
  ReadState st{&entries_, &sections_, stream, 0, 0, {}, {}};
  const int rc = ini_parse_stream(read_line, &st, handler, &st);
  if (rc < 0 || std::ferror(stream) != 0) {
    if (error != nullptr) *error = name + ": read error";
    return false;
  }
  // inih's rc is the first line it could not parse or whose handler failed; a failure
  // found here has its reason, so an earlier rc is a malformed line. Entries stop there.
  if (rc > 0 && (st.error_line == 0 || rc < st.error_line)) {
    problem_line_ = rc;
    problem_ = at(rc, "malformed line (expected [section] or key = value)");
  } else if (st.error_line != 0) {
    problem_line_ = st.error_line;
    problem_ = at(st.error_line, st.why);
  }
  while (!entries_.empty() && problem_line_ != 0 && entries_.back().line >= problem_line_) entries_.pop_back();
  return true;
}

bool IniDocument::load(const std::string& path, std::string* error) {
  std::FILE* f = open_config_file(path, error);
  if (f == nullptr) return false;
  const bool ok = read(f, path, error);
  std::fclose(f);
  return ok;
}

bool IniDocument::has_section(const std::string& section) const {
  for (const auto& s : sections_) {
    if (s.first == section) return true;
  }
  return false;
}

int IniDocument::line_of(const std::string& section, const std::string& key) const {
  for (const IniEntry& e : entries_) {
    if (e.section == section && e.key == key) return e.line;
  }
  return 0;
}

std::string IniDocument::locate(const std::string& why) const {
  const std::size_t dot = why.find('.');
  const std::size_t colon = why.find(':');
  if (dot == std::string::npos || colon == std::string::npos || dot > colon) return why;
  std::size_t end = dot + 1U;
  while (end < colon && (std::isalnum(static_cast<unsigned char>(why[end])) != 0 || why[end] == '_')) ++end;
  const int line = line_of(why.substr(0, dot), why.substr(dot + 1U, end - dot - 1U));
  return line == 0 ? why : at(line, why);
}

}  // namespace sdpslam::slam
