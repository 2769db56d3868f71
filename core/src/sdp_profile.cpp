#include "sdpslam/core/sdp_profile.h"

#include <cstring>

namespace sdpslam {

const char* to_string(SdpProfile profile) {
  switch (profile) {
    case SdpProfile::kPaper: return "paper";
    case SdpProfile::kAccurate: return "accurate";
  }
  return "?";
}

bool parse_sdp_profile(const char* text, SdpProfile* profile) {
  if (text == nullptr || profile == nullptr) return false;
  if (std::strcmp(text, "paper") == 0) {
    *profile = SdpProfile::kPaper;
    return true;
  }
  if (std::strcmp(text, "accurate") == 0) {
    *profile = SdpProfile::kAccurate;
    return true;
  }
  return false;
}

void apply_profile(SdpProfile profile, DpSlamOptions* bottom, SdpOptions* top) {
  // Both profiles: the paper's B (§IV, 60T/10B). kPaper names no other field, so a file's
  // keys and anything the caller already set stay as they are.
  if (bottom != nullptr) bottom->particle_count = kSdpBottomParticles;
  if (profile != SdpProfile::kAccurate) return;
  if (bottom != nullptr) {
    // Improved proposal; 8 beams per match candidate keeps 10 particles inside the CPU
    // budget (Intel: ~100-125 s of CPU for 2691 s of data).
    bottom->proposal = DpSlamOptions::Proposal::kScanMatch;
    bottom->match.beam_stride = 8U;
  }
  if (top != nullptr) {
    top->max_levels = 8U;
    top->loop_closure = true;
    top->loop_search_window_m = 6.0;
    top->loop_search_max_window_m = 16.0;
  }
}

}  // namespace sdpslam
