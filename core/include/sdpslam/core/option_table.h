#pragma once
// One table per options struct: each field's INI section and key, how it is reached,
// its kind, unit, range and a one-line doc. The struct's validate() checks every range
// from its table, then the checks that join fields; the INI readers (firmware-host/runtime/slam
// option_text.h), the shipped .ini files' test and `--print-config` read the same
// table, so a field is declared once. Tables are constant data: no heap, no OS.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <type_traits>

namespace sdpslam {

enum class OptionKind : std::uint8_t {
  kReal,    // double
  kU32,     // std::uint32_t
  kBool,    // bool
  kChoice,  // an enum class with std::uint8_t underneath, named by `choices`
  kF32,     // float
};

struct OptionChoice {
  const char* name;
  std::uint8_t value;
};

template <class Options>
struct OptionSpec {
  const char* section;  // INI section, e.g. "sdp"
  const char* key;      // INI key = the name in messages "section.key"
  OptionKind kind;
  void* (*field)(Options& options);  // the field's address in `options`
  double min;     // kReal, kU32: allowed range, closed unless min_open
  double max;
  bool min_open;  // the range is (min, max]
  const char* unit;  // "m", "rad", "s", "" (a count or a ratio)
  const char* doc;   // one line
  const OptionChoice* choices;  // kChoice: the names (null otherwise)
  std::uint8_t choice_count;
};

template <class Options>
struct OptionTable {
  const OptionSpec<Options>* rows;
  std::size_t count;

  const OptionSpec<Options>* begin() const { return rows; }
  const OptionSpec<Options>* end() const { return rows + count; }
  // The row of section.key; null when the table has none.
  const OptionSpec<Options>* find(const char* section, const char* key) const {
    for (const OptionSpec<Options>& r : *this) {
      if (same(r.section, section) && same(r.key, key)) return &r;
    }
    return nullptr;
  }
  // True iff some row belongs to `section`.
  bool has_section(const char* section) const {
    for (const OptionSpec<Options>& r : *this) {
      if (same(r.section, section)) return true;
    }
    return false;
  }

 private:
  static bool same(const char* a, const char* b) {
    while (*a != '\0' && *a == *b) {
      ++a;
      ++b;
    }
    return *a == *b;
  }
};

// Typed access to a row's field (the kind must match the row's).
template <class T, class Options>
T& option_field(const OptionSpec<Options>& spec, Options& options) {
  return *static_cast<T*>(spec.field(options));
}
template <class T, class Options>
const T& option_field(const OptionSpec<Options>& spec, const Options& options) {
  return *static_cast<const T*>(spec.field(const_cast<Options&>(options)));
}

// A number's value as a double (kReal, kU32, kF32), else the choice's or bool's value.
template <class Options>
double option_number(const OptionSpec<Options>& spec, const Options& options) {
  switch (spec.kind) {
    case OptionKind::kReal: return option_field<double>(spec, options);
    case OptionKind::kU32: return static_cast<double>(option_field<std::uint32_t>(spec, options));
    case OptionKind::kBool: return option_field<bool>(spec, options) ? 1.0 : 0.0;
    case OptionKind::kChoice: return static_cast<double>(option_field<std::uint8_t>(spec, options));
    case OptionKind::kF32: return static_cast<double>(option_field<float>(spec, options));
  }
  return 0.0;
}

// The name of a kChoice row's current value; null when it has none.
template <class Options>
const char* option_choice_name(const OptionSpec<Options>& spec, const Options& options) {
  const std::uint8_t v = option_field<std::uint8_t>(spec, options);
  for (std::uint8_t i = 0U; i < spec.choice_count; ++i) {
    if (spec.choices[i].value == v) return spec.choices[i].name;
  }
  return nullptr;
}

// True iff the row's field is within its range (a choice: one of its names). Otherwise
// writes "section.key: VALUE out of range [min, max]" (or "(min, max]") into `why`.
template <class Options>
bool option_in_range(const OptionSpec<Options>& spec, const Options& options, char* why, std::size_t n) {
  if (spec.kind == OptionKind::kBool) return true;
  if (spec.kind == OptionKind::kChoice) {
    if (option_choice_name(spec, options) != nullptr) return true;
    if (why != nullptr && n > 0U) std::snprintf(why, n, "%s.%s: not one of its names", spec.section, spec.key);
    return false;
  }
  const double v = option_number(spec, options);
  const bool ok = (spec.min_open ? v > spec.min : v >= spec.min) && v <= spec.max;
  if (!ok && why != nullptr && n > 0U) {
    if (spec.kind == OptionKind::kU32) {
      std::snprintf(why, n, "%s.%s: %llu out of range [%llu, %llu]", spec.section, spec.key,
                    static_cast<unsigned long long>(v), static_cast<unsigned long long>(spec.min),
                    static_cast<unsigned long long>(spec.max));
    } else {
      std::snprintf(why, n, "%s.%s: %g out of range %s%g, %g]", spec.section, spec.key, v, spec.min_open ? "(" : "[",
                    spec.min, spec.max);
    }
  }
  return ok;
}

// True iff every row of `table` is in range; else `why` names the first that is not.
template <class Options>
bool options_in_range(const OptionTable<Options>& table, const Options& options, char* why, std::size_t n) {
  for (const OptionSpec<Options>& r : table) {
    if (!option_in_range(r, options, why, n)) return false;
  }
  return true;
}

namespace option_detail {
template <class T, class U>
constexpr void* address(U* p) {
  static_assert(std::is_same<T, U>::value, "the option row's kind does not match its field's type");
  return p;
}
template <class E>
constexpr void* choice_address(E* p) {
  static_assert(std::is_enum<E>::value && sizeof(E) == 1U, "a choice is an enum class over std::uint8_t");
  return p;
}
}  // namespace option_detail

}  // namespace sdpslam

// Row makers for option tables (OPTIONS is the struct, MEMBER a field path inside it).
#define SDPSLAM_OPTION_REAL(OPTIONS, SECTION, KEY, MEMBER, MIN, MAX, UNIT, DOC)                                     \
  ::sdpslam::OptionSpec<OPTIONS> {                                                                                  \
    SECTION, KEY, ::sdpslam::OptionKind::kReal,                                                                     \
        [](OPTIONS& o) -> void* { return ::sdpslam::option_detail::address<double>(&o.MEMBER); }, MIN, MAX, false, \
        UNIT, DOC, nullptr, 0U                                                                                      \
  }
#define SDPSLAM_OPTION_REAL_OPEN(OPTIONS, SECTION, KEY, MEMBER, MIN, MAX, UNIT, DOC)                               \
  ::sdpslam::OptionSpec<OPTIONS> {                                                                                  \
    SECTION, KEY, ::sdpslam::OptionKind::kReal,                                                                     \
        [](OPTIONS& o) -> void* { return ::sdpslam::option_detail::address<double>(&o.MEMBER); }, MIN, MAX, true,  \
        UNIT, DOC, nullptr, 0U                                                                                      \
  }
#define SDPSLAM_OPTION_U32(OPTIONS, SECTION, KEY, MEMBER, MIN, MAX, UNIT, DOC)                                      \
  ::sdpslam::OptionSpec<OPTIONS> {                                                                                  \
    SECTION, KEY, ::sdpslam::OptionKind::kU32,                                                                      \
        [](OPTIONS& o) -> void* { return ::sdpslam::option_detail::address<std::uint32_t>(&o.MEMBER); },           \
        static_cast<double>(MIN), static_cast<double>(MAX), false, UNIT, DOC, nullptr, 0U                          \
  }
#define SDPSLAM_OPTION_BOOL(OPTIONS, SECTION, KEY, MEMBER, DOC)                                                     \
  ::sdpslam::OptionSpec<OPTIONS> {                                                                                  \
    SECTION, KEY, ::sdpslam::OptionKind::kBool,                                                                     \
        [](OPTIONS& o) -> void* { return ::sdpslam::option_detail::address<bool>(&o.MEMBER); }, 0.0, 1.0, false,   \
        "", DOC, nullptr, 0U                                                                                        \
  }
#define SDPSLAM_OPTION_CHOICE(OPTIONS, SECTION, KEY, MEMBER, CHOICES, DOC)                                          \
  ::sdpslam::OptionSpec<OPTIONS> {                                                                                  \
    SECTION, KEY, ::sdpslam::OptionKind::kChoice,                                                                   \
        [](OPTIONS& o) -> void* { return ::sdpslam::option_detail::choice_address(&o.MEMBER); }, 0.0, 0.0, false,  \
        "", DOC, CHOICES, static_cast<std::uint8_t>(sizeof(CHOICES) / sizeof(CHOICES[0]))                           \
  }
#define SDPSLAM_OPTION_F32(OPTIONS, SECTION, KEY, MEMBER, MIN, MAX, MIN_OPEN, UNIT, DOC)                            \
  ::sdpslam::OptionSpec<OPTIONS> {                                                                                  \
    SECTION, KEY, ::sdpslam::OptionKind::kF32,                                                                      \
        [](OPTIONS& o) -> void* { return ::sdpslam::option_detail::address<float>(&o.MEMBER); }, MIN, MAX,          \
        MIN_OPEN, UNIT, DOC, nullptr, 0U                                                                            \
  }
