#!/usr/bin/env python3
"""An independent MAVLink client (pymavlink) flies a drone of `aviary vehicles`.

Usage: takeoff_land.py AVIARY_BINARY WORLD_FILE

Starts `aviary vehicles --world WORLD --listen tcp:127.0.0.1:0 --speed 5`, reads the
port from its first line, then with pymavlink: waits for HEARTBEAT, sets GUIDED, arms
(again while the pre-arm checks fail), takes off to 10 m, reads GLOBAL_POSITION_INT
until the altitude is reached, lands and waits for the disarm. Every wait has a limit;
exit 0 on success, 1 with the step that failed.
"""
import subprocess
import sys
import time

from pymavlink import mavutil

ALTITUDE = 10.0


def fail(step):
    print(f"takeoff_land: FAILED: {step}", file=sys.stderr)
    sys.exit(1)


def until(limit, what, check):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        result = check()
        if result:
            return result
    fail(f"{what} (waited {limit} s)")


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    aviary, world = sys.argv[1], sys.argv[2]
    server = subprocess.Popen(
        [aviary, "vehicles", "--world", world, "--listen", "tcp:127.0.0.1:0", "--speed", "5"],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        first = server.stdout.readline().strip()
        if "listening on tcp:" not in first:
            fail(f"aviary vehicles did not start: {first!r}")
        address = first.split("listening on ")[1]
        print(f"takeoff_land: {first}")
        run(address)
    finally:
        server.terminate()
        server.wait(timeout=10)


def run(address):
    master = mavutil.mavlink_connection(address, source_system=255, source_component=190)
    hb = master.wait_heartbeat(timeout=10)
    if hb is None:
        fail("no HEARTBEAT")
    system = master.target_system
    print(f"takeoff_land: HEARTBEAT from system {system}, autopilot {hb.autopilot}, state {hb.system_status}")

    def heartbeat():
        return master.recv_match(type="HEARTBEAT", blocking=True, timeout=1)

    # GUIDED, asked again while the vehicle still boots (it ignores mode changes then).
    def guided():
        master.set_mode("GUIDED")
        m = heartbeat()
        return m is not None and m.get_srcSystem() == system and m.custom_mode == 4
    until(20, "switching to GUIDED", guided)
    print("takeoff_land: GUIDED")

    def command(cmd, *params):
        params = list(params) + [0] * (7 - len(params))
        master.mav.command_long_send(system, 1, cmd, 0, *params)
        ack = master.recv_match(type="COMMAND_ACK", blocking=True, timeout=2)
        while ack is not None and ack.command != cmd:
            ack = master.recv_match(type="COMMAND_ACK", blocking=True, timeout=2)
        return ack

    def arm():
        ack = command(mavutil.mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 1)
        if ack is not None and ack.result == mavutil.mavlink.MAV_RESULT_ACCEPTED:
            return True
        text = master.recv_match(type="STATUSTEXT", blocking=False)
        if text is not None:
            print(f"takeoff_land: not yet: {text.text}")
        time.sleep(0.5)
        return False
    until(30, "arming", arm)
    print("takeoff_land: armed")

    ack = command(mavutil.mavlink.MAV_CMD_NAV_TAKEOFF, 0, 0, 0, 0, 0, 0, ALTITUDE)
    if ack is None or ack.result != mavutil.mavlink.MAV_RESULT_ACCEPTED:
        fail(f"NAV_TAKEOFF refused: {ack}")

    def high_enough():
        p = master.recv_match(type="GLOBAL_POSITION_INT", blocking=True, timeout=1)
        return p is not None and p.get_srcSystem() == system and p.relative_alt >= (ALTITUDE - 0.5) * 1000
    until(60, f"climbing to {ALTITUDE} m", high_enough)
    print(f"takeoff_land: at {ALTITUDE} m")

    ack = command(mavutil.mavlink.MAV_CMD_NAV_LAND)
    if ack is None or ack.result != mavutil.mavlink.MAV_RESULT_ACCEPTED:
        fail(f"NAV_LAND refused: {ack}")

    def disarmed():
        m = heartbeat()
        armed = mavutil.mavlink.MAV_MODE_FLAG_SAFETY_ARMED
        return m is not None and m.get_srcSystem() == system and not (m.base_mode & armed)
    until(60, "landing", disarmed)
    print("takeoff_land: landed and disarmed: OK")


if __name__ == "__main__":
    main()
