// Whitespace-separated text tables (see text_table.h).
#include "sdpslam/io/text_table.h"

#include <cerrno>
#include <cstring>
#include <sstream>

namespace sdpslam::io {

bool read_table(std::istream& in, const std::string& name, const TableRow& row, std::string* error) {
  std::string line;
  std::int64_t line_no = 0;
  std::vector<std::string> tokens;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::size_t first = line.find_first_not_of(" \t");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    tokens.clear();
    for (std::string t; fields >> t;) tokens.push_back(t);
    const std::string why = row(tokens, line_no);
    if (!why.empty()) {
      if (error != nullptr) *error = name + ":" + std::to_string(line_no) + ": " + why;
      return false;
    }
  }
  if (in.bad()) {
    if (error != nullptr) *error = "read error on '" + name + "' after line " + std::to_string(line_no);
    return false;
  }
  return true;
}

bool open_for_reading(const std::string& path, std::ifstream* in, std::string* error) {
  in->open(path);
  if (*in) return true;
  if (error != nullptr) *error = "cannot open '" + path + "': " + std::strerror(errno);
  return false;
}

}  // namespace sdpslam::io
