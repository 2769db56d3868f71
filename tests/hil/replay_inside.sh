# Runs inside the virtual-CAN machine (tests/hil/run_in_vm.sh): the receiver integrates
# odometry from vcan0 while the player replays the candump onto it at SPEED.
# Arguments: PAIRS SPEED
pairs=$1
speed=$2
ip link add dev vcan0 type vcan && ip link set up vcan0 || exit 10
./hil_odom_receiver vcan0 ./replay.candump "$pairs" 1500 >/tmp/receiver.log 2>&1 &
rx=$!
i=0
until grep -q ready /tmp/receiver.log 2>/dev/null; do
  i=$((i + 1)); [ $i -gt 100 ] && { cat /tmp/receiver.log; exit 11; }
  sleep 0.1
done
./hil_can_player ./replay.candump vcan0 "$speed"
player_rc=$?
wait $rx
rx_rc=$?
cat /tmp/receiver.log
echo "player exit $player_rc, receiver exit $rx_rc"
[ $player_rc = 0 ] && [ $rx_rc = 0 ]
