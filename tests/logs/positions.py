#!/usr/bin/env python3
"""Prints the positions an autopilot logged of its own flight, one JSON array per line:
[latitude, longitude, height above home in metres].

    positions.py FLIGHT.ulg    PX4's ULog, read with pyulog: vehicle_global_position,
                               heights from home_position (else the first position, on
                               the ground at arming, where PX4 starts its log)
    positions.py FLIGHT.BIN    ArduPilot's DataFlash log, read with pymavlink's reader:
                               POS, heights RelHomeAlt

The real-autopilot suites (crates/aviary-cli/tests/px4_sitl.rs and sitl.rs) hold the
positions of Aviary's trace to these: the vehicle's own record of where it was.
"""
import json
import sys


def ulog(path):
    from pyulog import ULog

    log = ULog(path, ["vehicle_global_position", "home_position"])
    topics = {d.name: d.data for d in log.data_list}
    pos = topics["vehicle_global_position"]
    home = topics.get("home_position")
    ground = float(home["alt"][-1]) if home is not None and len(home["alt"]) else float(pos["alt"][0])
    for lat, lon, alt in zip(pos["lat"], pos["lon"], pos["alt"]):
        yield [float(lat), float(lon), float(alt) - ground]


def dataflash(path):
    from pymavlink import DFReader

    log = DFReader.DFReader_binary(path)
    while True:
        m = log.recv_match(type="POS")
        if m is None:
            return
        yield [m.Lat, m.Lng, m.RelHomeAlt]


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: positions.py FLIGHT.ulg|FLIGHT.BIN")
    path = sys.argv[1]
    read = ulog if path.lower().endswith(".ulg") else dataflash
    for p in read(path):
        print(json.dumps(p))


if __name__ == "__main__":
    main()
