#pragma once
// Whitespace-separated text tables, one record per line: trajectories, the benchmark's
// relations, a run's segments. Blank lines and lines whose first non-blank character is
// '#' are skipped; a trailing CR (a file written on Windows) is dropped.
#include <cstdint>
#include <fstream>
#include <functional>
#include <istream>
#include <string>
#include <vector>

namespace sdpslam::io {

// Calls row(tokens, line) for every record line of `in`, in order (line: 1-based in the
// file). row returns an empty string to go on, or why the line is bad: read_table then
// stops and returns false with "name:line: why" in *error (may be null). A stream that
// fails to read is "read error on 'name' after line N".
using TableRow = std::function<std::string(const std::vector<std::string>& tokens, std::int64_t line)>;
bool read_table(std::istream& in, const std::string& name, const TableRow& row, std::string* error);

// Opens `path` for reading; false with "cannot open 'path': reason" in *error otherwise.
bool open_for_reading(const std::string& path, std::ifstream* in, std::string* error);

}  // namespace sdpslam::io
