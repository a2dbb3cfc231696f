"""Decodes an MCAP file of JointState messages twice, with the `mcap-ros2-support` decoder and
with `rosbags` (its MCAP storage reader, its parser of the file's message definitions and its
CDR deserializer: what its AnyReader does for a rosbag2 folder, which needs a metadata.yaml
that a lone MCAP file does not have), and
prints one JSON object: {"mcap_ros2": [...], "rosbags": [...], "profile": ..., "schema": ...}
with every message as {"topic", "log_time", "sec", "nanosec", "name", "position"}.

Usage: read_mcap.py FILE.mcap
"""

import json
import sys
from pathlib import Path

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2.storage_mcap import McapReader
from rosbags.typesys import Stores, get_typestore, get_types_from_msg


def row(topic, log_time, m):
    return {
        "topic": topic,
        "log_time": log_time,
        "sec": m.header.stamp.sec,
        "nanosec": m.header.stamp.nanosec,
        "name": list(m.name),
        "position": [float(x) for x in m.position],
    }


def main():
    path = Path(sys.argv[1])
    out = {"mcap_ros2": [], "rosbags": []}
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        out["profile"] = reader.get_header().profile
        for schema, channel, message, m in reader.iter_decoded_messages():
            out["schema"] = [schema.name, schema.encoding, channel.message_encoding]
            out["mcap_ros2"].append(row(channel.topic, message.log_time, m))
    reader = McapReader(path)
    reader.open()
    try:
        types = {}
        for c in reader.connections:
            types.update(get_types_from_msg(c.msgdef.data, c.msgtype))
        store = get_typestore(Stores.EMPTY)
        store.register(types)
        for conn, t, raw in reader.messages(reader.connections):
            m = store.deserialize_cdr(raw, conn.msgtype)
            out["rosbags"].append(row(conn.topic, t, m))
    finally:
        reader.close()
    print(json.dumps(out))


if __name__ == "__main__":
    main()
