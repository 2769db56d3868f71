# Runs inside the virtual-CAN machine (tests/hil/run_in_vm.sh): the unmodified sdpslamd
# (static) reads encoder frames from vcan0 and the emulated URG on a pty, while the player
# replays the log on both at SPEED; SIGTERM at the end, then the outputs are printed
# between markers for the host to compare: the daemon's log, status.json as text, and the
# output directory (trajectory.txt, map.pgm, input.clf, ...) as a base64 tar.gz so the
# host gets every byte. Arguments: LINES SPEED
lines=$1
speed=$2
ip link add dev vcan0 type vcan && ip link set up vcan0 || exit 10
# The laser emulator needs pseudo-terminals: the machine's /init mounts no devpts.
mkdir -p /dev/pts && mount -t devpts -o ptmxmode=0666 devpts /dev/pts 2>/dev/null
[ -e /dev/ptmx ] || ln -s pts/ptmx /dev/ptmx
mkdir -p /tmp/out
./sdpslamd_static --config ./sdpslamd.ini --out /tmp/out 2>/tmp/daemon.log &
pid=$!
./sdpslamd_replay_static --log ./log.dat --link /tmp/laser --lines "$lines" --speed "$speed" --delay-s 4 \
  --can-iface vcan0 --candump ./ticks.candump
replay_rc=$?
sleep 2
kill -TERM $pid
wait $pid
daemon_rc=$?
cat /tmp/daemon.log
echo "@@STATUS"
cat /tmp/out/status.json
echo "@@OUTPUTS"
( cd /tmp/out && tar cf - . ) | gzip -c | base64
echo "@@END"
ls /tmp/out | grep -q '\.tmp' && echo "temporary files left in /tmp/out" && daemon_rc=20
echo "replay exit $replay_rc, sdpslamd exit $daemon_rc"
[ $replay_rc = 0 ] && [ $daemon_rc = 0 ]
