"""An independent Zenoh client watches and steers `aviary run --zenoh`.

eclipse-zenoh from PyPI (pinned by .ci/run), which no one here wrote, connects to the
run's endpoint and holds the payloads to docs/DISTRIBUTED.md: every event on
PREFIX/events and every sample on PREFIX/telemetry/DRONE is one JSON object of the trace
(`t`, `event`; a sample's `actor` is the key's last chunk), PREFIX/state is the operator
state (`status`, `drones`), and PREFIX/api/CALL answers as the HTTP API does: reading
with no token, a control without the token refused, with it accepted. Each event's
attachment is its place in the run, and PREFIX/api/history holds the events so far, the
same lines in the same places; PREFIX/api/mission gives the mission's name, tree and map.

    python tests/zenoh/watch.py path/to/aviary
"""

import json
import os
import socket
import subprocess
import sys
import tempfile
import time

import zenoh

WORLD = "[places]\nFar = [0, 400]\n[drones.a]\nhome = [0, 0]\n[drones.b]\nhome = [10, 0]\n"
MISSION = "MISSION M:\n    PARALLEL:\n        a FlyTo-F1 WITH Far\n        b Hover WITH 40s\n"


def fail(why):
    print(f"zenoh_watch: FAILED: {why}", file=sys.stderr)
    sys.exit(1)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def peer(endpoints, port):
    return (
        '{ mode: "peer", %s: { endpoints: ["tcp/127.0.0.1:%d"] }, '
        "scouting: { multicast: { enabled: false }, gossip: { enabled: false } } }" % (endpoints, port)
    )


def ask_text(session, key, token=None):
    """The one reply to a query: (ok, the text it carries)."""
    kwargs = {"attachment": token} if token else {}
    for reply in session.get(key, timeout=5.0, **kwargs):
        if reply.ok is not None:
            return True, reply.ok.payload.to_string()
        return False, reply.err.payload.to_string()
    fail(f"no reply on {key}")


def ask(session, key, token=None):
    """The one reply to a query: (ok, the JSON it carries)."""
    ok, text = ask_text(session, key, token)
    return ok, json.loads(text)


def main():
    aviary = os.path.abspath(sys.argv[1])
    work = tempfile.mkdtemp(prefix="aviary-zenoh-")
    with open(os.path.join(work, "m.mission"), "w") as f:
        f.write(MISSION)
    with open(os.path.join(work, "m.world.toml"), "w") as f:
        f.write(WORLD)
    port = free_port()
    with open(os.path.join(work, "zenoh.json5"), "w") as f:
        f.write(peer("listen", port))
    run = subprocess.Popen(
        [aviary, "run", "m.mission", "--zenoh", "zenoh.json5", "--speed", "10", "--quiet"],
        cwd=work,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    first = run.stderr.readline()
    if "on Zenoh under aviary/M/" not in first:
        fail(f"the run did not say where it publishes: {first!r}")
    token = first.split()[-1]

    session = zenoh.open(zenoh.Config.from_json5(peer("connect", port)))
    heard = session.declare_subscriber("aviary/M/**")
    ok, state = ask(session, "aviary/M/api/state")
    if not ok or not isinstance(state.get("drones"), list):
        fail(f"the state query: {state}")
    ok, shown = ask(session, "aviary/M/api/mission")
    if not ok or shown.get("mission") != "M" or shown["tree"].get("name") != "M" or "map" not in shown:
        fail(f"the mission query: {shown}")
    ok, history = ask_text(session, "aviary/M/api/history")
    if not ok:
        fail(f"the history query: {history}")
    ok, refused = ask(session, "aviary/M/api/pause")
    if ok or "token" not in refused.get("error", ""):
        fail(f"a pause without the token was not refused: {refused}")
    ok, accepted = ask(session, "aviary/M/api/abort", token)
    if not ok:
        fail(f"an abort with the token was refused: {accepted}")

    events, places, lines, telemetry, states, ended = [], [], {}, {}, [], False
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not (ended and states and states[-1]["status"] != "running"):
        sample = heard.try_recv()
        if sample is None:
            time.sleep(0.02)
            continue
        key = str(sample.key_expr)
        if str(sample.encoding) != "application/json":
            fail(f"{key} is encoded {sample.encoding}")
        payload = json.loads(sample.payload.to_string())
        if key == "aviary/M/events":
            if not isinstance(payload.get("t"), (int, float)) or "event" not in payload:
                fail(f"an event without t or event: {payload}")
            place = int(sample.attachment.to_string()) if sample.attachment is not None else None
            if events and place != places[-1] + 1:
                fail(f"event {payload} at place {place} after {places[-1]}")
            places.append(place)
            lines[place] = sample.payload.to_string()
            events.append(payload)
            ended = ended or payload["event"] == "mission_end"
        elif key.startswith("aviary/M/telemetry/"):
            drone = key.rsplit("/", 1)[1]
            if payload.get("event") != "telemetry" or payload.get("actor") != drone:
                fail(f"{key} carries {payload}")
            telemetry.setdefault(drone, []).append(payload)
        elif key == "aviary/M/state":
            states.append(payload)
        else:
            fail(f"a key docs/DISTRIBUTED.md does not list: {key}")
    # The history, asked after the subscription began, holds the same lines in the same
    # places as heard, and reaches the first one heard: none is missed between the two.
    first, *past = history.splitlines()
    dropped = json.loads(first)["dropped"]
    if not places or places[0] > dropped + len(past):
        fail(f"the first event heard is at {places[:1]}, after a history of {len(past)}")
    for place, line in lines.items():
        if dropped <= place < dropped + len(past) and past[place - dropped] != line:
            fail(f"history place {place}: {past[place - dropped]!r}, heard {line!r}")
    session.close()
    code = run.wait(timeout=30)
    if not ended:
        fail("no mission_end on aviary/M/events")
    if not any(e["event"] == "operator" and e.get("action") == "abort" for e in events):
        fail("the abort was not heard")
    if states[-1]["status"] == "running" or set(telemetry) != {"a", "b"}:
        fail(f"last state {states[-1]['status']}, telemetry of {sorted(telemetry)}")
    print(f"zenoh_watch: {len(events)} events, {sum(map(len, telemetry.values()))} samples, "
          f"{len(states)} states, run exit {code}, ended {states[-1]['status']}: OK")


if __name__ == "__main__":
    main()
