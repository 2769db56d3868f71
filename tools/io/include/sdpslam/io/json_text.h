#pragma once
// Text pieces of the JSON files the programs write (stats.json, status.json, evaluate
// --json): a string as a JSON string literal (quotes, backslashes and control characters
// escaped, RFC 8259 §7), and a number as JSON allows it (non-finite values as null).
#include <string>

namespace sdpslam::io {

std::string json_quote(const std::string& text);
std::string json_number(double value);

}  // namespace sdpslam::io
