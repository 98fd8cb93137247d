"""Load on Zenoh: N simulated drones (`aviary bench swarm`) flown in real time at H
telemetry samples a second each, published by `aviary run --zenoh`, and received by a
peer in another process (eclipse-zenoh from PyPI). Prints the samples received per
second and the lag of each sample (when it arrived, less when it was due: the run's
first sample's arrival plus its mission time), in the first and the last seconds, so
that a lag that grows shows.

With `--router ZENOHD`, the run and the receiver are Zenoh clients of a `zenohd` router
that the script starts, as a mission and a station on two machines would be. With
`--check`, it fails (exit 1) unless 95 % of the samples arrived and the median lag of the
last 5 s is within 250 ms of the first 5 s's: `.ci/run` runs it so.

    python bench/zenoh_load.py ./target/release/aviary [--drones 1000] [--hz 10] [--seconds 60] [--router zenohd] [--check]
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
    parser.add_argument("--router", help="a zenohd binary: both sides are its clients")
    parser.add_argument("--check", action="store_true", help="fail unless the samples arrive and the lag holds")
    args = parser.parse_args()
    aviary = os.path.abspath(args.aviary)
    work = tempfile.mkdtemp(prefix="aviary-zenoh-load-")
    for flag, name in (("--emit", "swarm.mission"), ("--emit-world", "swarm.world.toml")):
        with open(os.path.join(work, name), "w") as f:
            subprocess.run([aviary, "bench", "swarm", "--drones", str(args.drones), flag], stdout=f, check=True)
    port = free_port()
    no_scouting = "scouting: { multicast: { enabled: false }, gossip: { enabled: false } }"
    router = None
    if args.router:
        router = subprocess.Popen(
            [os.path.abspath(args.router), "--listen", "tcp/127.0.0.1:%d" % port, "--no-multicast-scouting"],
            cwd=work, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )
        # A client gives up at once on a router that does not listen yet.
        deadline = time.monotonic() + 30
        while True:
            try:
                socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise SystemExit("zenohd does not listen")
                time.sleep(0.05)
        run_side = receiver = '{ mode: "client", connect: { endpoints: ["tcp/127.0.0.1:%d"] } }' % port
    else:
        run_side = '{ mode: "peer", listen: { endpoints: ["tcp/127.0.0.1:%d"] }, %s }' % (port, no_scouting)
        receiver = '{ mode: "peer", connect: { endpoints: ["tcp/127.0.0.1:%d"] }, %s }' % (port, no_scouting)
    with open(os.path.join(work, "zenoh.json5"), "w") as f:
        f.write(run_side)
    run = subprocess.Popen(
        [aviary, "run", "swarm.mission", "--world", "swarm.world.toml", "--zenoh", "zenoh.json5",
         "--zenoh-prefix", "load", "--speed", "1", "--telemetry-hz", str(args.hz), "--quiet"],
        cwd=work, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )
    run.stderr.readline()
    session = zenoh.open(zenoh.Config.from_json5(receiver))
    arrivals = []  # (arrival, mission time)

    def heard(sample):
        arrivals.append((time.monotonic(), json.loads(sample.payload.to_string())["t"]))

    subscriber = session.declare_subscriber("load/telemetry/*", heard)
    time.sleep(args.seconds)
    subscriber.undeclare()
    session.close()
    run.terminate()
    run.wait(timeout=30)
    if router:
        router.terminate()
        router.wait(timeout=30)
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
    if args.check:
        rate = len(arrivals) / span / (args.drones * args.hz)
        grown = ms(late, 50) - ms(early, 50)
        if rate < 0.95 or not grown < 250:
            raise SystemExit(f"zenoh_load: FAILED: {rate:.1%} of the samples arrived, the median lag grew {grown:.0f} ms")
        print(f"zenoh_load: {rate:.1%} of the samples arrived, the median lag moved {grown:.0f} ms: OK")


if __name__ == "__main__":
    main()
