#pragma once
// A tree and a map sized together from one arena, as the filter does it.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <vector>

#include "sdpslam/core/bottom/ancestry_tree.h"
#include "sdpslam/core/bottom/dp_map.h"

namespace sdpslam::test {

struct DpFixture {
  std::vector<unsigned char> buffer;
  Arena arena;
  AncestryTree tree;
  DpMap map;

  DpFixture(std::uint32_t nodes, std::uint32_t paths, const DpMap::Options& o) {
    buffer.resize(AncestryTree::required_arena_bytes(nodes, paths) + DpMap::required_arena_bytes(o, nodes));
    arena.reset(buffer.data(), buffer.size());
    CHECK_TRUE(tree.init(arena, nodes, paths));
    CHECK_TRUE(map.init(arena, o, tree));
  }
};

// 2.4 m × 2.0 m at 5 cm: 48 × 40 cells, 3 × 3 tiles of 16 (the last row partly outside).
inline DpMap::Options small_options(std::uint32_t tiles, std::uint32_t observations) {
  DpMap::Options o;
  o.origin_x_m = -1.0;
  o.origin_y_m = 2.0;
  o.width_m = 2.4;
  o.height_m = 2.0;
  o.resolution_m = 0.05;
  o.tile_capacity = tiles;
  o.observation_capacity = observations;
  return o;
}

}  // namespace sdpslam::test
