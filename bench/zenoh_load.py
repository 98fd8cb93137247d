"""Load on Zenoh: N simulated drones (`aviary bench swarm`) flown in real time at H
telemetry samples a second each, published by `aviary run --zenoh`, and received by a
peer in another process (eclipse-zenoh from PyPI). Prints the samples received per
second and the lag of each sample (when it arrived, less when it was due: the run's
first sample's arrival plus its mission time), in the first and the last seconds, so
that a lag that grows shows.

    python bench/zenoh_load.py ./target/release/aviary [--drones 1000] [--hz 10] [--seconds 60]
"""

import argparse
import json
import os
import socket
import statistics
import subprocess
import tempfile
import time

import zenoh


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("aviary")
    parser.add_argument("--drones", type=int, default=1000)
    parser.add_argument("--hz", type=float, default=10)
    parser.add_argument("--seconds", type=float, default=60)
    args = parser.parse_args()
    aviary = os.path.abspath(args.aviary)
    work = tempfile.mkdtemp(prefix="aviary-zenoh-load-")
    for flag, name in (("--emit", "swarm.mission"), ("--emit-world", "swarm.world.toml")):
        with open(os.path.join(work, name), "w") as f:
            subprocess.run([aviary, "bench", "swarm", "--drones", str(args.drones), flag], stdout=f, check=True)
    port = free_port()
    no_scouting = "scouting: { multicast: { enabled: false }, gossip: { enabled: false } }"
    with open(os.path.join(work, "zenoh.json5"), "w") as f:
        f.write('{ mode: "peer", listen: { endpoints: ["tcp/127.0.0.1:%d"] }, %s }' % (port, no_scouting))
    run = subprocess.Popen(
        [aviary, "run", "swarm.mission", "--world", "swarm.world.toml", "--zenoh", "zenoh.json5",
         "--zenoh-prefix", "load", "--speed", "1", "--telemetry-hz", str(args.hz), "--quiet"],
        cwd=work, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )
    run.stderr.readline()
    session = zenoh.open(zenoh.Config.from_json5(
        '{ mode: "peer", connect: { endpoints: ["tcp/127.0.0.1:%d"] }, %s }' % (port, no_scouting)))
    arrivals = []  # (arrival, mission time)

    def heard(sample):
        arrivals.append((time.monotonic(), json.loads(sample.payload.to_string())["t"]))

    subscriber = session.declare_subscriber("load/telemetry/*", heard)
    time.sleep(args.seconds)
    subscriber.undeclare()
    session.close()
    run.terminate()
    run.wait(timeout=30)
    if not arrivals:
        raise SystemExit("no telemetry arrived")
    first_arrival, first_t = arrivals[0]
    lags = [(a - first_arrival, (a - first_arrival) - (t - first_t)) for a, t in arrivals]
    span = lags[-1][0]
    early = [lag for at, lag in lags if at < 5]
    late = [lag for at, lag in lags if at > span - 5]

    def ms(values, q):
        return 1000 * statistics.quantiles(values, n=100)[q - 1] if len(values) > 1 else float("nan")

    print(f"{args.drones} drones at {args.hz:g} Hz for {span:.0f} s: {len(arrivals)} samples, "
          f"{len(arrivals) / span:.0f} a second (expected {args.drones * args.hz:.0f})")
    print(f"lag, first 5 s: median {ms(early, 50):.1f} ms, 95th {ms(early, 95):.1f} ms")
    print(f"lag, last 5 s:  median {ms(late, 50):.1f} ms, 95th {ms(late, 95):.1f} ms")


if __name__ == "__main__":
    main()
