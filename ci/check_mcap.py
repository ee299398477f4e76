"""An independent reader of `--mcap-out`: the Python `mcap` and
`mcap-ros2-support` packages decode every message with the schemas the file
carries and check what the campaign's summary says.

Usage: check_mcap.py FILE.mcap SUMMARY.json [KNOWLEDGE.yaml]
"""

import json
import sys
from collections import Counter

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory

TOPICS = {
    "/map": "nav_msgs/msg/OccupancyGrid",
    "/cpsplan/scans": "sensor_msgs/msg/PointCloud2",
    "/cpsplan/stations": "geometry_msgs/msg/PoseWithCovarianceStamped",
    "/cpsplan/path/parent": "nav_msgs/msg/Path",
    "/cpsplan/plan": "visualization_msgs/msg/MarkerArray",
    "/tf": "tf2_msgs/msg/TFMessage",
}


def main(path, summary_path, knowledge=None):
    summary = json.load(open(summary_path))
    scans = summary["scans"]
    counts = Counter()
    last_map = None
    points = 0
    times = []
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message, ros in reader.iter_decoded_messages():
            counts[channel.topic] += 1
            assert schema.encoding == "ros2msg", schema.encoding
            assert channel.message_encoding == "cdr"
            if channel.topic in TOPICS:
                assert schema.name == TOPICS[channel.topic], (channel.topic, schema.name)
            if channel.topic == "/map":
                last_map = ros
                w, h = ros.info.width, ros.info.height
                assert len(ros.data) == w * h, (len(ros.data), w, h)
                assert set(ros.data) <= {-1, 0, 100}, set(ros.data)
                assert ros.header.frame_id == "map"
            elif channel.topic == "/cpsplan/scans":
                assert ros.point_step == 12 and [f.name for f in ros.fields] == ["x", "y", "z"]
                assert len(ros.data) == 12 * ros.width * ros.height
                points += ros.width * ros.height
            elif channel.topic == "/cpsplan/stations":
                assert len(ros.pose.covariance) == 36
            elif channel.topic == "/tf":
                names = [t.child_frame_id for t in ros.transforms]
                assert names[0] == "parent", names
            elif channel.topic == "/cpsplan/plan":
                for m in ros.markers:
                    assert m.header.frame_id == "map"
            times.append(message.log_time)
    for topic in TOPICS:
        assert counts[topic] > 0, f"no message on {topic}: {dict(counts)}"
    assert counts["/cpsplan/scans"] == scans, (counts["/cpsplan/scans"], scans)
    assert counts["/cpsplan/stations"] == scans
    assert counts["/map"] == scans
    assert points > 0
    if knowledge is not None:
        import pathlib
        yaml = pathlib.Path(knowledge).read_text()
        fields = dict(line.split(":", 1) for line in yaml.splitlines() if ":" in line and not line.startswith("#"))
        resolution = float(fields["resolution"])
        origin = [float(v) for v in fields["origin"].strip().strip("[]").split(",")]
        assert abs(last_map.info.resolution - resolution) < 1e-6, (last_map.info.resolution, resolution)
        assert abs(last_map.info.origin.position.x - origin[0]) < 1e-9
        assert abs(last_map.info.origin.position.y - origin[1]) < 1e-9
        pgm = pathlib.Path(knowledge).with_suffix(".pgm").read_bytes()
        parts = pgm.split(b"\n", 3)
        w, h = map(int, parts[1].split())
        assert (last_map.info.width, last_map.info.height) == (w, h)
        pixels = parts[3]
        value = {254: 0, 0: 100, 205: -1}
        for y in range(h):
            row = pixels[(h - 1 - y) * w:(h - y) * w]
            got = last_map.data[y * w:(y + 1) * w]
            assert [value[p] for p in row] == list(got), f"row {y} differs"
    print(f"mcap ok: {sum(counts.values())} messages on {len(counts)} topics, "
          f"{scans} scans, {points} points, map {last_map.info.width} x {last_map.info.height}")


if __name__ == "__main__":
    main(*sys.argv[1:])
