// The [sdp] section of the shipped INI and its parser.
#include <CppUTest/TestHarness.h>

#include <fstream>
#include <string>

#include "sdpslam/slam/config_ini.h"
#include "sdpslam/slam/run_sdp.h"
#include "shared_data.h"

using namespace sdpslam;

TEST_GROUP(SdpConfig){};

TEST(SdpConfig, shipped_default_sdp_section_loads_and_equals_the_built_in_defaults) {
  SdpOptions o;
  o.top_particles = 7U;  // the file must set it back
  o.max_levels = 3U;
  std::string error;
  CHECK_TRUE_TEXT(slam::load_sdp_ini(SDPSLAM_DEFAULT_INI, &o, &error), error.c_str());
  const SdpOptions d;
  LONGS_EQUAL(d.top_particles, o.top_particles);
  LONGS_EQUAL(d.max_levels, o.max_levels);
  DOUBLES_EQUAL(d.period_travel_m, o.period_travel_m, 0.0);
  DOUBLES_EQUAL(d.elite_fraction, o.elite_fraction, 0.0);
  DOUBLES_EQUAL(d.icp.max_correspondence_m, o.icp.max_correspondence_m, 0.0);
  LONGS_EQUAL(d.icp.max_iterations, o.icp.max_iterations);
  LONGS_EQUAL(d.skeleton_points, o.skeleton_points);
  LONGS_EQUAL(static_cast<int>(d.accumulation), static_cast<int>(o.accumulation));
  LONGS_EQUAL(static_cast<int>(d.segmentation), static_cast<int>(o.segmentation));
  // ... and the bottom-level loader skips the [sdp] section.
  slam::SlamConfig c;
  CHECK_TRUE_TEXT(slam::load_config_ini(SDPSLAM_DEFAULT_INI, &c, &error), error.c_str());
}

TEST(SdpConfig, unknown_or_out_of_range_sdp_keys_are_rejected_with_file_and_line) {
  const std::string dir = sdpslam::test::make_temp_dir("sdp_config");
  const std::string path = dir + "/c.ini";
  std::ofstream(path) << "[filter]\nparticles = 5\n[sdp]\ntop_particles = 20\nmax_levels = 1\n";
  SdpOptions o;
  std::string error;
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  CHECK_TRUE_TEXT(error.find(path + ":5:") != std::string::npos, error.c_str());
  CHECK_TRUE_TEXT(error.find("max_levels") != std::string::npos, error.c_str());
  std::ofstream(path) << "[sdp]\nno_such_key = 1\n";
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  CHECK_TRUE_TEXT(error.find(":2:") != std::string::npos && error.find("no_such_key") != std::string::npos,
                  error.c_str());
  std::ofstream(path) << "[sdp]\ntopology = global\n";
  CHECK_FALSE(slam::load_sdp_ini(path, &o, &error));
  CHECK_TRUE_TEXT(error.find("topology") != std::string::npos, error.c_str());
}

TEST(SdpConfig, enumerated_keys_take_their_names) {
  SdpOptions o;
  std::string why;
  CHECK(slam::apply_sdp_key(&o, "topology", "segslam", &why) == slam::SdpKeyResult::kApplied);
  CHECK(o.topology == TopologyMode::kSegSlam);
  CHECK(slam::apply_sdp_key(&o, "segmentation", "dispersion", &why) == slam::SdpKeyResult::kApplied);
  CHECK(o.segmentation == SegmentationMode::kDispersion);
  CHECK(slam::apply_sdp_key(&o, "accumulation", "mean", &why) == slam::SdpKeyResult::kApplied);
  CHECK(o.accumulation == PgsAccumulation::kMean);
  CHECK_FALSE(o.map_owner_cell_index);
  CHECK(slam::apply_sdp_key(&o, "map_owner_cell_index", "true", &why) == slam::SdpKeyResult::kApplied);
  CHECK_TRUE(o.map_owner_cell_index);
  CHECK(slam::apply_sdp_key(&o, "map_owner_cell_index", "1", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "elite_fraction", "abc", &why) == slam::SdpKeyResult::kInvalid);
  CHECK(slam::apply_sdp_key(&o, "nothing", "1", &why) == slam::SdpKeyResult::kUnknown);
}
