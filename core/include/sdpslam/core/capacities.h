#pragma once
// Build-time capacities of the core, one place for all of them.
//
// Each value can be overridden for a build profile with -DSDPSLAM_<NAME>=value; the
// static_asserts keep every value inside the range the algorithms are written for.
// Run-time sized storage (grid tiles, observation pools) is chosen at init from
// options and carved from an Arena; its upper bounds live here too.
#include <cstddef>
#include <cstdint>

namespace sdpslam::capacity {

#ifndef SDPSLAM_MAX_BOTTOM_PARTICLES
#define SDPSLAM_MAX_BOTTOM_PARTICLES 512
#endif
#ifndef SDPSLAM_MAX_BEAMS
#define SDPSLAM_MAX_BEAMS 1081
#endif

// Bottom-level (DP-SLAM) particles; the DP-SLAM baseline runs up to this many.
inline constexpr std::uint32_t kMaxBottomParticles = SDPSLAM_MAX_BOTTOM_PARTICLES;
static_assert(kMaxBottomParticles >= 1U && kMaxBottomParticles <= 4096U, "kMaxBottomParticles out of range");

// Beams in one laser scan (1081 covers a 270 deg / 0.25 deg scanner; URG-04LX has 682).
inline constexpr std::uint32_t kMaxBeams = SDPSLAM_MAX_BEAMS;
static_assert(kMaxBeams >= 2U && kMaxBeams <= 4096U, "kMaxBeams out of range");

}  // namespace sdpslam::capacity
