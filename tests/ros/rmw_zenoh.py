"""ROS 2 clients that no one here wrote see `aviary run --zenoh --ros` as rmw_zenoh
publishers (docs/ROS2.md).

- zenoh-ros2-sdk (PyPI, an rmw_zenoh client in Python: its own key expressions, type
  hashes and liveliness tokens) subscribes to /aviary/a/fix as sensor_msgs/msg/NavSatFix
  and receives the drone's positions on the Earth.
- eclipse-zenoh (PyPI) looks at the wire: the node's and each publisher's liveliness
  tokens under @ros2_lv/0/; each key's type hash is the one rosbags (PyPI) computes for
  the type (aviary_msgs/msg/Event too, from its definition); each sample's attachment is
  rmw_zenoh's 33 bytes with the publisher's sequence numbers from 1; each payload is CDR
  that rosbags decodes.

    python tests/ros/rmw_zenoh.py path/to/aviary

zenoh-ros2-sdk reads message definitions from a folder beside it (or fetches them with
git, which CI cannot): the test writes the four it needs there, ROS 2's own text.
"""

import json
import os
import socket
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import zenoh
import zenoh_ros2_sdk
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from zenoh_ros2_sdk import ROS2Subscriber
from zenoh_ros2_sdk.session import ZenohSession

ORIGIN = (46.6167, 14.2650, 440.0)
WORLD = f"""[site]
origin = {{ lat = {ORIGIN[0]}, lon = {ORIGIN[1]}, alt = {ORIGIN[2]} }}
[places]
Far = [0, 400]
[drones.a]
home = [0, 0]
[drones.b]
home = [10, 0]
"""
MISSION = "MISSION M:\n    PARALLEL:\n        a FlyTo-F1 WITH Far\n        b Hover WITH 20s\n"

# ROS 2's own definitions (common_interfaces, rcl_interfaces), as zenoh-ros2-sdk reads them.
DEFINITIONS = {
    "sensor_msgs/msg/NavSatFix": "uint8 COVARIANCE_TYPE_UNKNOWN = 0\nuint8 COVARIANCE_TYPE_APPROXIMATED = 1\nuint8 COVARIANCE_TYPE_DIAGONAL_KNOWN = 2\nuint8 COVARIANCE_TYPE_KNOWN = 3\nstd_msgs/Header header\nNavSatStatus status\nfloat64 latitude\nfloat64 longitude\nfloat64 altitude\nfloat64[9] position_covariance\nuint8 position_covariance_type\n",
    "sensor_msgs/msg/NavSatStatus": "int8 STATUS_NO_FIX = -1\nint8 STATUS_FIX = 0\nint8 STATUS_SBAS_FIX = 1\nint8 STATUS_GBAS_FIX = 2\nint8 status\nuint16 SERVICE_GPS = 1\nuint16 SERVICE_GLONASS = 2\nuint16 SERVICE_COMPASS = 4\nuint16 SERVICE_GALILEO = 8\nuint16 service\n",
    "std_msgs/msg/Header": "builtin_interfaces/Time stamp\nstring frame_id\n",
    "builtin_interfaces/msg/Time": "int32 sec\nuint32 nanosec\n",
}
# The project's own message, as docs/ROS2.md gives it.
EVENT = "std_msgs/Header header\nstring event\nstring json\n"


def fail(why):
    print(f"rmw_zenoh: FAILED: {why}", file=sys.stderr)
    sys.exit(1)


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def main():
    aviary = os.path.abspath(sys.argv[1])
    messages = Path(zenoh_ros2_sdk.__file__).parent.parent / "messages"
    for name, text in DEFINITIONS.items():
        path = messages / f"{name}.msg"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)

    work = tempfile.mkdtemp(prefix="aviary-ros-")
    Path(work, "m.mission").write_text(MISSION)
    Path(work, "m.world.toml").write_text(WORLD)
    port = free_port()
    Path(work, "zenoh.json5").write_text(
        '{ mode: "peer", listen: { endpoints: ["tcp/127.0.0.1:%d"] }, '
        "scouting: { multicast: { enabled: false }, gossip: { enabled: false } } }" % port
    )
    run = subprocess.Popen(
        [aviary, "run", "m.mission", "--zenoh", "zenoh.json5", "--ros", "--speed", "4", "--quiet"],
        cwd=work,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    first = run.stderr.readline()
    if "on Zenoh under aviary/M/" not in first:
        fail(f"the run did not say where it publishes: {first!r}")

    fixes = []
    heard = threading.Event()

    def on_fix(msg):
        fixes.append(msg)
        heard.set()

    sdk = ROS2Subscriber(topic="/aviary/a/fix", msg_type="sensor_msgs/msg/NavSatFix",
                         callback=on_fix, router_ip="127.0.0.1", router_port=port)

    session = zenoh.open(zenoh.Config.from_json5(
        '{ mode: "client", connect: { endpoints: ["tcp/127.0.0.1:%d"] } }' % port))
    samples = []
    session.declare_subscriber("0/aviary/**", lambda s: samples.append(
        (str(s.key_expr), s.payload.to_bytes(), s.attachment.to_bytes() if s.attachment is not None else None)))

    if not heard.wait(30):
        fail(f"zenoh-ros2-sdk heard no NavSatFix on /aviary/a/fix; the wire had {sorted({k for k, _, _ in samples})}")
    time.sleep(1.0)
    tokens = [str(r.ok.key_expr) for r in session.liveliness().get("@ros2_lv/0/**", timeout=5.0) if r.ok]
    run.wait(timeout=120)

    # What zenoh-ros2-sdk decoded: where drone a is, about the world's origin.
    fix = fixes[-1]
    if abs(fix.latitude - ORIGIN[0]) > 0.01 or abs(fix.longitude - ORIGIN[1]) > 0.01:
        fail(f"drone a's fix is at {fix.latitude}, {fix.longitude}, not near the origin {ORIGIN}")
    if fix.header.frame_id != "map" or fix.status.status != 0:
        fail(f"the fix's header or status: {fix}")

    # The wire, read with rosbags' own types and hashes.
    store = get_typestore(Stores.ROS2_JAZZY)
    store.register(get_types_from_msg(EVENT, "aviary_msgs/msg/Event"))
    kinds = {
        "sensor_msgs::msg::dds_::NavSatFix_": "sensor_msgs/msg/NavSatFix",
        "geometry_msgs::msg::dds_::PoseStamped_": "geometry_msgs/msg/PoseStamped",
        "aviary_msgs::msg::dds_::Event_": "aviary_msgs/msg/Event",
    }
    sequences = {}
    for key, payload, attachment in samples:
        *topic, dds, hash_ = key.split("/")[1:]
        ty = kinds.get(dds) or fail(f"a type rmw_zenoh would not name: {key}")
        if hash_ != store.hash_rihs01(ty):
            fail(f"{key}: the hash is not rosbags' {store.hash_rihs01(ty)}")
        if attachment is None or len(attachment) != 33 or attachment[16] != 16:
            fail(f"{key}: the attachment is not rmw_zenoh's 33 bytes: {attachment!r}")
        sequence = int.from_bytes(attachment[0:8], "little", signed=True)
        stamp = int.from_bytes(attachment[8:16], "little", signed=True)
        if sequence != sequences.get(key, sequence - 1) + 1 or abs(stamp / 1e9 - time.time()) > 600:
            fail(f"{key}: sequence {sequence} after {sequences.get(key)}, stamp {stamp}")
        sequences[key] = sequence
        message = store.deserialize_cdr(payload, ty)
        if ty == "aviary_msgs/msg/Event" and json.loads(message.json)["event"] != message.event:
            fail(f"an event's kind and its line disagree: {message}")
    topics = {"/" + "/".join(k.split("/")[1:-2]) for k, _, _ in samples}
    want = {"/aviary/events", "/aviary/a/fix", "/aviary/a/pose", "/aviary/b/fix", "/aviary/b/pose"}
    if not want <= topics:
        fail(f"topics heard {sorted(topics)}, not all of {sorted(want)}")
    node = [t for t in tokens if t.endswith("/NN/%/%/aviary")]
    publishers = [t for t in tokens if "/MP/%/%/aviary/%aviary%a%fix/sensor_msgs::msg::dds_::NavSatFix_/RIHS01_" in t]
    if len(node) != 1 or len(publishers) != 1:
        fail(f"the liveliness tokens: {tokens}")
    print(f"rmw_zenoh: zenoh-ros2-sdk decoded {len(fixes)} NavSatFix; {len(samples)} samples on "
          f"{len(topics)} topics, hashes, attachments and CDR as rmw_zenoh's; {len(tokens)} tokens: OK")
    # Both sessions closed, or their threads keep the interpreter from ending.
    sdk.close()
    ZenohSession.get_instance().close()
    session.close()


if __name__ == "__main__":
    main()
