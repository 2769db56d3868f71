# The sensor sections of sdpslamd's configuration for the tinySLAM robot whose log the
# end-to-end tests replay: wheel ticks as CANopen position PDOs of nodes 1 and 2, a URG
# laser (SCIP 2.0) mounted 0.145 m ahead of the axle. Sourced by the test scripts.
#   tinyslam_sensors LASER_DEVICE [CAN_INTERFACE [MAX_INTERPOLATION_GAP_MS]]
# (the [sync] section comes last: more [sync] keys may follow).
tinyslam_sensors() {
  echo "[can]"
  if [ -n "${2:-}" ]; then echo "interface = $2"; fi
  cat <<INI
protocol = canopen
left_node = 1
right_node = 2
sync_period_ms = 0
position_timeout_ms = 500
[laser]
device = $1
protocol = scip
stall_timeout_ms = 5000
x_m = 0.145
[sync]
odometry_wait_ms = 400
max_interpolation_gap_ms = ${3:-500}
INI
}

# SDP-SLAM small enough for a few hundred lines of the log: 10 top particles, a segment
# every 4 processed scans, 3 live levels (several segments end and older levels become
# permanent). Keys in this order: each [sdp] key is validated as it is read, and
# periodic segmentation needs some period at every step.
small_sdp_section() {
  cat <<INI
[sdp]
top_particles = 10
period_scans = 4
period_travel_m = 0
min_segment_scans = 3
max_segment_scans = 30
max_levels = 3
map_tile_capacity = 2000
map_observation_capacity = 400000
INI
}
