#pragma once
// Small file-system helpers for tests that write into a temporary folder.
#include <string>
#include <vector>

namespace sdpslam::test {

// The whole contents of a file; empty when it cannot be read.
std::string read_file(const std::string& path);
// The names in a folder (no "." or ".."), sorted; empty when it cannot be listed.
std::vector<std::string> list_dir(const std::string& dir);
// Removes a folder and everything under it (symbolic links are not followed).
void remove_tree(const std::string& dir);

}  // namespace sdpslam::test
