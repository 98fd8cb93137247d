#!/usr/bin/env python3
"""An independent ground station (MAVProxy) flies a drone of `aviary vehicles`.

Usage: fly.py AVIARY_BINARY WORLD_FILE

Starts `aviary vehicles --world WORLD --listen tcp:127.0.0.1:0 --speed 5`, reads the
port from its first line, then drives MAVProxy through its command line (stdin), as a
person types: waits for the parameter download to complete, `mode guided`, `arm
throttle`, `takeoff 10`, `guided LAT LON 10` to a point 30 m north of home, reads the
position back (`status GLOBAL_POSITION_INT`) until it is there, `rtl`, and waits for the
disarm. Then checks what MAVProxy printed: every command acknowledged as accepted, the
link never down, (almost) no packet loss, no error or traceback. Every wait has a limit;
exit 0 on success, 1 with the step that failed (and MAVProxy's output).
"""
import math
import os
import queue
import re
import subprocess
import sys
import tempfile
import threading
import time

SPEED = 5
ALTITUDE = 10.0
NORTH = 30.0
EARTH_RADIUS = 6_371_000.0


class Proxy:
    """MAVProxy as a child process, its output collected line by line."""

    def __init__(self, address, workdir):
        command = [
            sys.executable, "-u", "-m", "MAVProxy.mavproxy",
            f"--master={address}", "--target-system=1", "--no-state",
        ]
        env = dict(os.environ, MPLBACKEND="Agg")
        env.pop("DISPLAY", None)
        self.process = subprocess.Popen(
            command, cwd=workdir, env=env, text=True, bufsize=1,
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
        )
        self.lines = []
        self.fresh = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.process.stdout:
            line = line.rstrip("\n")
            self.lines.append(line)
            self.fresh.put(line)

    def send(self, command):
        print(f"mavproxy_fly: > {command}")
        self.process.stdin.write(command + "\n")
        self.process.stdin.flush()

    def expect(self, pattern, limit, step):
        """The first new line matching `pattern` within `limit` seconds."""
        deadline = time.monotonic() + limit
        while time.monotonic() < deadline:
            try:
                line = self.fresh.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                break
            m = re.search(pattern, line)
            if m:
                return m
        fail(f"{step}: no line matching {pattern!r} in {limit} s", self)

    def stop(self):
        if self.process.poll() is None:
            try:
                self.send("exit")
                self.process.wait(timeout=5)
            except (BrokenPipeError, subprocess.TimeoutExpired):
                self.process.kill()
                self.process.wait(timeout=5)


def fail(step, proxy=None):
    if proxy is not None:
        print("mavproxy_fly: MAVProxy's output:", file=sys.stderr)
        for line in proxy.lines[-80:]:
            print(f"    {line}", file=sys.stderr)
    print(f"mavproxy_fly: FAILED: {step}", file=sys.stderr)
    sys.exit(1)


def main():
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    aviary, world = sys.argv[1], sys.argv[2]
    started = time.monotonic()
    server = subprocess.Popen(
        [aviary, "vehicles", "--world", world, "--listen", "tcp:127.0.0.1:0", "--speed", str(SPEED)],
        stdout=subprocess.PIPE, text=True,
    )
    proxy = None
    try:
        first = server.stdout.readline().strip()
        if "listening on tcp:" not in first:
            fail(f"aviary vehicles did not start: {first!r}")
        address = first.split("listening on ")[1]
        print(f"mavproxy_fly: {first}")
        with tempfile.TemporaryDirectory() as workdir:
            proxy = Proxy(address, workdir)
            fly(proxy)
            check(proxy)
            print("mavproxy_fly: MAVProxy's output:")
            for line in proxy.lines:
                print(f"    {line}")
    finally:
        if proxy is not None:
            proxy.stop()
        server.terminate()
        server.wait(timeout=10)
    print(f"mavproxy_fly: OK in {time.monotonic() - started:.0f} s")


def position(proxy):
    """(lat, lon, relative altitude in m) from `status GLOBAL_POSITION_INT`."""
    proxy.send("status GLOBAL_POSITION_INT")
    m = proxy.expect(r"GLOBAL_POSITION_INT \{.*lat : (-?\d+), lon : (-?\d+), alt : -?\d+, relative_alt : (-?\d+)",
                     5, "reading the position")
    return int(m.group(1)) / 1e7, int(m.group(2)) / 1e7, int(m.group(3)) / 1000.0


def until(proxy, limit, step, check):
    deadline = time.monotonic() + limit
    while time.monotonic() < deadline:
        if check():
            return
        time.sleep(0.5)
    fail(f"{step} (waited {limit} s)", proxy)


def fly(proxy):
    proxy.expect(r"Detected vehicle 1:1", 20, "detecting the vehicle")
    proxy.expect(r"Received \d+ parameters", 30, "downloading the parameters")
    print("mavproxy_fly: parameters received")

    # GUIDED, asked again while the vehicle still boots (it refuses mode changes then).
    def guided():
        proxy.send("mode guided")
        m = proxy.expect(r"Got COMMAND_ACK: DO_SET_MODE: (\w+)", 5, "switching to GUIDED")
        return m.group(1) == "ACCEPTED"
    until(proxy, 20, "switching to GUIDED", guided)
    proxy.expect(r"Mode GUIDED", 5, "GUIDED in the HEARTBEAT")

    # Armed once the pre-arm checks pass (the simulated GPS fix).
    def arm():
        proxy.send("arm throttle")
        m = proxy.expect(r"Got COMMAND_ACK: COMPONENT_ARM_DISARM: (\w+)", 5, "arming")
        return m.group(1) == "ACCEPTED"
    until(proxy, 30, "arming", arm)
    proxy.expect(r"^ARMED", 5, "armed in the HEARTBEAT")
    print("mavproxy_fly: armed")

    proxy.send(f"takeoff {ALTITUDE:g}")
    m = proxy.expect(r"Got COMMAND_ACK: NAV_TAKEOFF: (\w+)", 5, "taking off")
    if m.group(1) != "ACCEPTED":
        fail(f"take-off refused: {m.group(0)}", proxy)
    home = position(proxy)
    until(proxy, 30, f"climbing to {ALTITUDE:g} m", lambda: position(proxy)[2] >= ALTITUDE - 0.5)
    print(f"mavproxy_fly: at {ALTITUDE:g} m")

    lat = home[0] + math.degrees(NORTH / EARTH_RADIUS)
    lon = home[1]
    proxy.send(f"guided {lat:.7f} {lon:.7f} {ALTITUDE:g}")
    m = proxy.expect(r"Got COMMAND_ACK: DO_REPOSITION: (\w+)", 5, "guided goto")
    if m.group(1) != "ACCEPTED":
        fail(f"guided goto refused: {m.group(0)}", proxy)

    def arrived():
        p = position(proxy)
        north = math.radians(p[0] - lat) * EARTH_RADIUS
        east = math.radians(p[1] - lon) * EARTH_RADIUS * math.cos(math.radians(lat))
        return math.hypot(north, east) < 2.0 and abs(p[2] - ALTITUDE) < 1.0
    until(proxy, 30, f"flying {NORTH:g} m north", arrived)
    print(f"mavproxy_fly: arrived {NORTH:g} m north")

    proxy.send("rtl")
    proxy.expect(r"Got COMMAND_ACK: DO_SET_MODE: ACCEPTED|RTL>", 5, "RTL")
    proxy.expect(r"DISARMED", 60, "returning and landing")
    print("mavproxy_fly: landed at home and disarmed")


# What MAVProxy says when a vehicle lacks something it needs.
COMPLAINTS = [
    r"link \d+ down",
    r"[Nn]o parameters",
    r"Traceback",
    r"[Ee]xception",
    r"ERROR",
    r"UNSUPPORTED|DENIED|FAILED|[Ff]ailed",
    r"[Tt]imeout",
    r"unknown message|Unknown message",
]


def check(proxy):
    proxy.send("link")
    m = proxy.expect(r"link \d+ OK \((\d+) packets, .*, (\d+) lost, ([\d.]+)% loss", 5, "link status")
    packets, lost, loss = int(m.group(1)), int(m.group(2)), float(m.group(3))
    print(f"mavproxy_fly: link: {packets} packets, {lost} lost ({loss}%)")
    if loss > 0.5:
        fail(f"MAVProxy counted {loss}% packet loss", proxy)
    for line in proxy.lines:
        for pattern in COMPLAINTS:
            if re.search(pattern, line):
                fail(f"MAVProxy complained: {line!r}", proxy)


if __name__ == "__main__":
    main()
