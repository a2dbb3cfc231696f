"""A ROS 2 JointState subscriber that is not ROS: Eclipse Cyclone DDS (the PyPI `cyclonedds`
package, the DDS under ROS 2's default middleware) reading `sensor_msgs/msg/JointState` on a
topic, as `ros2 topic echo` would, and writing every sample it received as one JSON line.

Usage: subscriber.py --out FILE [--topic /joint_states] [--ready FILE] [--idle S] [--timeout S]

The DDS domain is ROS_DOMAIN_ID (default 0). It writes --ready once the reader exists, then
stops --idle seconds after the last sample (after the first one) or at --timeout, whichever
comes first. QoS: reliable, volatile, keep all (what the test counts is what arrived).
"""

import argparse
import json
import os
import time
from dataclasses import dataclass

import cyclonedds.idl.annotations as annotate
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import float64, int32, sequence, uint32
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration


# The message types as ROS 2's IDL names them (package::msg::dds_::Type_).
@dataclass
@annotate.final
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32
    nanosec: uint32


@dataclass
@annotate.final
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
@annotate.final
class JointState(IdlStruct, typename="sensor_msgs::msg::dds_::JointState_"):
    header: Header
    name: sequence[str]
    position: sequence[float64]
    velocity: sequence[float64]
    effort: sequence[float64]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--topic", default="/joint_states")
    ap.add_argument("--ready")
    ap.add_argument("--idle", type=float, default=3.0)
    ap.add_argument("--timeout", type=float, default=120.0)
    a = ap.parse_args()
    domain = int(os.environ.get("ROS_DOMAIN_ID", "0") or 0)
    dp = DomainParticipant(domain)
    # ROS 2 topic /a/b is DDS topic rt/a/b.
    topic = Topic(dp, "rt/" + a.topic.lstrip("/"), JointState)
    qos = Qos(
        Policy.Reliability.Reliable(duration(seconds=1)),
        Policy.Durability.Volatile,
        Policy.History.KeepAll,
    )
    reader = DataReader(dp, topic, qos=qos)
    if a.ready:
        with open(a.ready, "w") as f:
            f.write("ready\n")
    start = time.monotonic()
    last = None
    n = 0
    with open(a.out, "w") as out:
        while True:
            now = time.monotonic()
            if now - start > a.timeout or (last is not None and now - last > a.idle):
                break
            got = reader.take(N=1000)
            if not got:
                time.sleep(0.005)
                continue
            last = time.monotonic()
            for m in got:
                # The writer leaving shows as an invalid sample (no data): not a message.
                if not isinstance(m, JointState):
                    continue
                out.write(
                    json.dumps(
                        {
                            "sec": m.header.stamp.sec,
                            "nanosec": m.header.stamp.nanosec,
                            "frame_id": m.header.frame_id,
                            "name": list(m.name),
                            "position": list(m.position),
                            "velocity": list(m.velocity),
                            "effort": list(m.effort),
                        }
                    )
                    + "\n"
                )
                n += 1
    print(f"received {n} JointState messages on {a.topic} (domain {domain})")


if __name__ == "__main__":
    main()
