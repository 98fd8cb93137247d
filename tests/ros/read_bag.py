"""Reads a bag `aviary export --mcap` wrote, with rosbags (PyPI), a reader no one here
wrote: every message is decoded through the definitions the bag carries, and a summary
is printed as JSON for crates/aviary-cli/tests/ros_bag.rs to hold to the trace.

    target/pyenv/bin/python tests/ros/read_bag.py BAG
"""
import json
import sys
from pathlib import Path

from rosbags.highlevel import AnyReader


def main(bag: str) -> None:
    topics = {}
    fixes = {}
    poses = {}
    events = []
    with AnyReader([Path(bag)]) as reader:
        for connection, timestamp, raw in reader.messages():
            msg = reader.deserialize(raw, connection.msgtype)
            t = msg.header.stamp.sec + msg.header.stamp.nanosec / 1e9
            assert abs(t - timestamp / 1e9) < 1e-6, (t, timestamp)
            topic = topics.setdefault(connection.topic, {"type": connection.msgtype, "count": 0})
            topic["count"] += 1
            if connection.msgtype == "aviary_msgs/msg/Event":
                line = json.loads(msg.json)
                assert line["event"] == msg.event, (line, msg.event)
                events.append([t, msg.event])
            elif connection.msgtype == "sensor_msgs/msg/NavSatFix":
                drone = connection.topic.split("/")[2]
                fixes[drone] = [t, msg.latitude, msg.longitude, msg.altitude, msg.status.status]
            elif connection.msgtype == "geometry_msgs/msg/PoseStamped":
                drone = connection.topic.split("/")[2]
                p = msg.pose.position
                poses[drone] = [t, p.x, p.y, p.z, msg.header.frame_id]
    print(json.dumps({"topics": topics, "last_fix": fixes, "last_pose": poses, "events": events}))


if __name__ == "__main__":
    main(sys.argv[1])
