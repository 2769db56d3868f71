#pragma once
// yaml-cpp keeps function-local statics (its scanner's regular expressions, the spellings
// of booleans) that are allocated on first use and live until exit. CppUTest's leak check
// would blame them on whichever test first reads a YAML. Including this header in a test
// executable reads map YAMLs of every construct the map reader meets, well formed and
// not, during static initialisation, before any test runs.
#include <sstream>
#include <string>

#include "sdpslam/io/map_read.h"

namespace sdpslam::test {

inline const bool kYamlStaticsAllocated = [] {
  for (const char* text : {"image: \"m.pgm\"  # comment\nmode: 'trinary'\nresolution: 0.05\n"
                           "origin: [-1.0, 2.0, 0.0]\nnegate: false\noccupied_thresh: 0.65\nfree_thresh: 0.196\n",
                           "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0\n", "- a\n- b\n", "a:\n  b: c\n d: e\n"}) {
    std::istringstream in(text);
    io::MapYaml yaml;
    std::string error;
    io::parse_map_yaml(in, "warm-up.yaml", &yaml, &error);
  }
  return true;
}();

}  // namespace sdpslam::test
