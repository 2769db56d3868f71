#include "sdpslam/io/json_text.h"

#include <cmath>

namespace sdpslam::io {
namespace {

std::string scalar_text(const Json& value) {
  return value.dump(-1, ' ', false, Json::error_handler_t::replace);
}

bool is_flat(const Json& container) {
  for (const Json& member : container) {
    if (member.is_structured() && !member.empty()) return false;
  }
  return true;
}

void append(const Json& value, int indent, std::string* out) {
  if (!value.is_structured() || value.empty()) {
    *out += scalar_text(value);
    return;
  }
  const bool object = value.is_object();
  const bool flat = is_flat(value);
  const std::string inner(static_cast<std::size_t>(indent) + 2U, ' ');
  *out += object ? '{' : '[';
  bool first = true;
  for (auto it = value.begin(); it != value.end(); ++it) {
    if (!first) *out += ',';
    first = false;
    if (flat) {
      if (it != value.begin()) *out += ' ';
    } else {
      *out += '\n';
      *out += inner;
    }
    if (object) {
      *out += scalar_text(Json(it.key()));
      *out += ": ";
    }
    append(it.value(), indent + 2, out);
  }
  if (!flat) {
    *out += '\n';
    out->append(static_cast<std::size_t>(indent), ' ');
  }
  *out += object ? '}' : ']';
}

}  // namespace

std::string json_text(const Json& doc) {
  std::string out;
  append(doc, 0, &out);
  out += '\n';
  return out;
}

double json_fixed(double value, int decimals) {
  if (!std::isfinite(value)) return value;
  const double scale = std::pow(10.0, decimals < 0 ? 0 : decimals > 9 ? 9 : decimals);
  const double scaled = value * scale;
  return std::isfinite(scaled) ? std::round(scaled) / scale : value;
}

}  // namespace sdpslam::io
