#pragma once
// Named starting points for SDP-SLAM's options: what `sdpslam run` (sdp mode) and sdpslamd
// (mode = sdp) begin from before a configuration file's keys are applied.
//
//  Both      — kSdpBottomParticles bottom-level particles, the B of the paper's 60T/10B
//              (§IV); DP-SLAM alone (mode dpslam) keeps DpSlamOptions' 30.
//  kPaper    — the paper's algorithm (SDP-SLAM §III): otherwise DpSlamOptions{} and
//              SdpOptions{} as declared: odometry proposals, no loop closure.
//  kAccurate — the default of the tools and the onboard program, judged by the accuracy
//              benchmark over every log and built-in world (tools/bench/accuracy.sh,
//              worst seed). Beyond the paper:
//              the bottom level draws each particle around its scan match to its own
//              submap (Grisetti et al. 2007; every 8th beam scores a candidate, for the
//              CPU budget), and the top level closes loops: ICP constraints between
//              overlapping submaps of the best combination plus a wide correlative search
//              (±6 m, ±0.6 rad) of each new submap against older ones it may revisit
//              (correlative_matcher.h), with the submap frames adjusted to them
//              (frame_graph.h). 8 live PGS levels instead of 12, so that fewer submaps
//              hold DP-map observations at once within the 64 MiB budget.
//
// apply_profile() sets only the fields a profile names; everything else keeps its value,
// so a profile is applied first and a file's keys on top of it.
#include <cstdint>

#include "sdpslam/core/dpslam_options.h"
#include "sdpslam/core/sdp_options.h"

namespace sdpslam {

enum class SdpProfile : std::uint8_t { kPaper, kAccurate };

// Bottom-level particles per segment in sdp mode (both profiles).
constexpr std::uint32_t kSdpBottomParticles = 10U;

// The profile the tools and sdpslamd use when none is named.
constexpr SdpProfile kDefaultSdpProfile = SdpProfile::kAccurate;

// "paper" | "accurate".
const char* to_string(SdpProfile profile);
// True iff `text` is a profile's name; *profile is then set.
bool parse_sdp_profile(const char* text, SdpProfile* profile);

// Sets the fields `profile` names in *bottom and *top (either may be null).
void apply_profile(SdpProfile profile, DpSlamOptions* bottom, SdpOptions* top);

}  // namespace sdpslam
