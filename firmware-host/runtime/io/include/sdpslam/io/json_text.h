#pragma once
// The JSON files the programs write (stats.json, status.json, evaluate --json): built as
// nlohmann::ordered_json documents (members stay in the order they were added) and
// serialised by nlohmann, which escapes every string (RFC 8259 §7) and writes every
// number so that it reads back to the same value, a non-finite one as null.
//
// json_text() only decides where lines break, so that the files keep the layout their
// readers grep (tools/bench/*.sh, tests/sdpslamd/*.sh): an object or array whose members
// are all scalars is one line, `{"count": 3, "peak": 7}`; any other has one member per
// line, indented two spaces per level. Every token, keys included, is nlohmann's.
#include <string>

#include <nlohmann/json.hpp>

namespace sdpslam::io {

using Json = nlohmann::ordered_json;

// The text of `doc`, ending with a newline. Bytes of a string that are not UTF-8 are
// written as U+FFFD (JSON text is UTF-8, RFC 8259 §8.1); never throws.
std::string json_text(const Json& doc);

// `value` rounded to `decimals` decimal places (0..9): a measurement written no finer than
// it is meaningful (timings to the microsecond as "%.3f" ms did). Non-finite values are
// returned unchanged, and so written as null.
double json_fixed(double value, int decimals);

}  // namespace sdpslam::io
