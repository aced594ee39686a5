#!/usr/bin/env python3
"""Writes a small RadarScenes dataset root from the public schema (radar-scenes.github.io and the
reader oleschum/radar_scenes), with h5py and numpy only: not through dualgrid's writer.

The sequence: the ego drives straight at 10 m/s along heading 0.3 rad (sequence coordinates);
a car (track 'car-1', label 0) drives 14 m/s on the lane to its left, starting 12 m ahead; two
rows of static reflectors (label 11) line the road. Four corner radars at RadarScenes' default
mounting scan at about 13 Hz each, staggered, with float32 fields where the data set has them.

--widths narrow|wide: the field types. narrow (default) as the published files: float32 where
the data set has it, uint64 timestamps, uint8 sensor and label ids, fixed-length bytes. wide:
every float a float64 (x_seq big-endian), int64 timestamps and sensor ids, big-endian int16
labels, variable-length bytes for uuid and track_id; the values are the narrow file's (rounded
through float32 first), so a reader that converts widths correctly reads both the same.
--labels none: without label_id and track_id (unlabelled data).
--mutate KIND writes a broken variant (tests/hostile): see MUTATIONS.
"""
import argparse
import json
import os

import h5py
import numpy as np

MOUNTS = {1: (3.663, -0.873, -1.48418552), 2: (3.86, -0.70, -0.436185662),
          3: (3.86, 0.70, 0.436), 4: (3.663, 0.873, 1.484)}
FOV = np.radians(60.0)
EGO_SPEED, HEADING = 10.0, 0.3
CAR_SPEED, CAR_LEN, CAR_WID = 14.0, 4.5, 1.8
MUTATIONS = ["missing_dataset", "missing_field", "wrong_type", "index_out_of_range",
             "index_overlap", "odometry_not_increasing", "nan_detections", "nan_odometry",
             "empty_sequence", "truncated", "bad_sensor", "not_json", "sensors_not_number",
             "missing_h5", "label_out_of_range", "row_timestamp", "float_timestamp"]


def rot(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def ego_rear(t):
    d = np.array([np.cos(HEADING), np.sin(HEADING)])
    return np.array([100.0, 50.0]) + EGO_SPEED * t * d


def car_centre(t):
    d = np.array([np.cos(HEADING), np.sin(HEADING)])
    left = np.array([-np.sin(HEADING), np.cos(HEADING)])
    return ego_rear(0.0) + (14.0 + CAR_SPEED * t) * d + 3.5 * left


# Field types per --widths (radar_data, odometry); the rest of both datasets are float64.
VLEN_BYTES = h5py.vlen_dtype(bytes)
NARROW = {"timestamp": "<u8", "sensor_id": "u1", "range_sc": "<f4", "azimuth_sc": "<f4",
          "rcs": "<f4", "vr": "<f4", "vr_compensated": "<f4", "x_cc": "<f4", "y_cc": "<f4",
          "x_seq": "<f8", "y_seq": "<f8", "uuid": "S32", "track_id": "S32", "label_id": "u1"}
WIDE = {"timestamp": "<i8", "sensor_id": "<i8", "range_sc": "<f8", "azimuth_sc": "<f8",
        "rcs": "<f8", "vr": "<f8", "vr_compensated": "<f8", "x_cc": "<f8", "y_cc": "<f8",
        "x_seq": ">f8", "y_seq": "<f8", "uuid": VLEN_BYTES, "track_id": VLEN_BYTES,
        "label_id": ">i2"}
ODO_NARROW = {"timestamp": "<u8", "vx": "<f4", "yaw_rate": "<f4"}
ODO_WIDE = {"timestamp": "<i8", "vx": "<f8", "yaw_rate": "<f8"}
ODO_FIELDS = ["timestamp", "x_seq", "y_seq", "yaw_seq", "vx", "yaw_rate"]


def f32(v):
    """The value as the narrow file stores it (float32), as a float64."""
    return float(np.float32(v))


def make(out, duration, seed, widths="narrow", labels=True):
    rng = np.random.default_rng(seed)
    root = out
    seq_dir = os.path.join(root, "data", "sequence_1")
    os.makedirs(seq_dir, exist_ok=True)
    with open(os.path.join(root, "sensors.json"), "w") as f:
        json.dump({f"radar_{k}": {"id": k, "x": x, "y": y, "yaw": yaw}
                   for k, (x, y, yaw) in MOUNTS.items()}, f)
    with open(os.path.join(root, "sequences.json"), "w") as f:
        json.dump({"sequences": {"sequence_1": {"category": "validation", "scenes": 0}}}, f)

    t0 = 1_600_000_000_000_000  # microseconds, like the data set's
    # Odometry at 100 Hz.
    odo_t = t0 + np.arange(0, int(duration * 1e6) + 20_000, 10_000, dtype=np.uint64)
    odo_types = ODO_WIDE if widths == "wide" else ODO_NARROW
    odo = np.zeros(len(odo_t), dtype=[(n, odo_types.get(n, "<f8")) for n in ODO_FIELDS])
    odo["timestamp"] = odo_t
    for i, t in enumerate(odo_t):
        p = ego_rear((int(t) - t0) / 1e6)
        odo["x_seq"][i], odo["y_seq"][i] = p
    odo["yaw_seq"] = HEADING
    odo["vx"] = EGO_SPEED

    # Static reflectors: two rows 6 m left and right of the ego's line, every 4 m.
    d = np.array([np.cos(HEADING), np.sin(HEADING)])
    left = np.array([-np.sin(HEADING), np.cos(HEADING)])
    statics = [ego_rear(0.0) + s * d + o * left for s in np.arange(-20, 180, 4.0)
               for o in (-6.0, 9.0)]

    # Scan times: each radar every ~75 ms (13.3 Hz), staggered by ~19 ms.
    scans = []
    for k in MOUNTS:
        t = (k - 1) * 0.019
        while t < duration:
            scans.append((t0 + int(round(t * 1e6)), k))
            t += 0.075 + rng.uniform(-0.002, 0.002)
    scans.sort()
    rows, scene_entries = [], {}
    for ts, k in scans:
        t = (ts - t0) / 1e6
        j = int(np.argmin(np.abs(odo_t.astype(np.int64) - ts)))
        rear, yaw = np.array([odo["x_seq"][j], odo["y_seq"][j]]), HEADING
        mx, my, myaw = MOUNTS[k]
        spos = rear + rot(yaw) @ np.array([mx, my])
        syaw = yaw + myaw
        v_ego = EGO_SPEED * d
        start = len(rows)

        def add(p, vel, label, track):
            rel = rot(syaw).T @ (p - spos)
            rng_m, az = np.hypot(*rel), np.arctan2(rel[1], rel[0])
            if rng_m > 100.0 or abs(az) > FOV:
                return
            u = (p - spos) / rng_m
            vr_comp = float(vel @ u) + rng.normal(0, 0.05)
            vr = vr_comp - float(v_ego @ u)
            cc = rot(yaw).T @ (p - rear)
            rows.append((ts, k, f32(rng_m), f32(az), f32(rng.uniform(-10, 10)), f32(vr),
                         f32(vr_comp), f32(cc[0]), f32(cc[1]), p[0], p[1],
                         rng.bytes(16).hex().encode(), track, label))

        c = car_centre(t)
        for _ in range(rng.integers(3, 7)):
            local = np.array([rng.uniform(-CAR_LEN / 2, CAR_LEN / 2),
                              rng.uniform(-CAR_WID / 2, CAR_WID / 2)])
            add(c + rot(HEADING) @ local, CAR_SPEED * d, 0, b"car-1")
        for s in statics:
            if rng.uniform() < 0.3:
                add(s + rng.normal(0, 0.1, 2), np.zeros(2), 11, b"")
        scene_entries[ts] = dict(sensor_id=k, radar_indices=[start, len(rows)], odometry_index=j,
                                 odometry_timestamp=int(odo_t[j]), image_name="")
    keys = sorted(scene_entries)
    last_same = {}
    for i, ts in enumerate(keys):
        e = scene_entries[ts]
        e["prev_timestamp"] = keys[i - 1] if i > 0 else None
        e["next_timestamp"] = keys[i + 1] if i + 1 < len(keys) else None
        e["prev_timestamp_same_sensor"] = last_same.get(e["sensor_id"])
        e["next_timestamp_same_sensor"] = None
        if e["sensor_id"] in last_same:
            scene_entries[last_same[e["sensor_id"]]]["next_timestamp_same_sensor"] = ts
        last_same[e["sensor_id"]] = ts
    types = WIDE if widths == "wide" else NARROW
    names = list(NARROW)
    radar = np.array(rows, dtype=[(n, types[n]) for n in names])
    if not labels:
        keep = [n for n in names if n not in ("track_id", "label_id")]
        radar = np.array(radar[keep].tolist(), dtype=[(n, types[n]) for n in keep])
    scenes = {"sequence_name": "sequence_1", "first_timestamp": keys[0],
              "last_timestamp": keys[-1], "scenes": {str(t): scene_entries[t] for t in keys}}
    return seq_dir, radar, odo, scenes


def write(seq_dir, radar, odo, scenes):
    with h5py.File(os.path.join(seq_dir, "radar_data.h5"), "w") as f:
        f.create_dataset("radar_data", data=radar)
        f.create_dataset("odometry", data=odo)
    with open(os.path.join(seq_dir, "scenes.json"), "w") as f:
        json.dump(scenes, f)


def mutate(kind, seq_dir, radar, odo, scenes):
    first = scenes["scenes"][str(scenes["first_timestamp"])]
    second_key = sorted(int(k) for k in scenes["scenes"])[1]
    if kind == "missing_dataset":
        write(seq_dir, radar, odo, scenes)
        with h5py.File(os.path.join(seq_dir, "radar_data.h5"), "w") as f:
            f.create_dataset("radar_data", data=radar)  # no odometry
        return
    if kind == "missing_field":
        names = [n for n in radar.dtype.names if n != "x_seq"]
        radar = np.array(radar[names].tolist(), dtype=[(n, radar.dtype[n]) for n in names])
    elif kind == "wrong_type":
        dt = [(n, "S8" if n == "vr_compensated" else radar.dtype[n]) for n in radar.dtype.names]
        radar = np.array([tuple(str(v).encode() if n == "vr_compensated" else v
                                for n, v in zip(radar.dtype.names, r)) for r in radar.tolist()],
                         dtype=dt)
    elif kind == "index_out_of_range":
        first["radar_indices"] = [0, len(radar) + 5]
    elif kind == "index_overlap":
        scenes["scenes"][str(second_key)]["radar_indices"][0] = max(
            0, first["radar_indices"][1] - 1)
        first["radar_indices"][1] = max(first["radar_indices"][1], 1)
    elif kind == "odometry_not_increasing":
        odo["timestamp"][5] = odo["timestamp"][4]
    elif kind == "nan_detections":
        radar["x_seq"][-3:] = np.nan
        radar["vr_compensated"][-3:] = np.nan
    elif kind == "nan_odometry":
        odo["x_seq"][first["odometry_index"]] = np.nan
    elif kind == "empty_sequence":
        scenes["scenes"] = {}
    elif kind == "bad_sensor":
        first["sensor_id"] = 7
    elif kind == "label_out_of_range":
        radar["label_id"][first["radar_indices"][0]] = 12
    elif kind == "row_timestamp":  # a row of the first scene stamped 1 us later
        radar["timestamp"][first["radar_indices"][0]] += 1
    elif kind == "float_timestamp":  # microseconds as float64: not an integer field
        dt = [(n, "<f8" if n == "timestamp" else radar.dtype[n]) for n in radar.dtype.names]
        radar = radar.astype(dt)
    write(seq_dir, radar, odo, scenes)
    if kind == "sensors_not_number":
        path = os.path.join(os.path.dirname(os.path.dirname(seq_dir)), "sensors.json")
        sensors = json.load(open(path))
        sensors["radar_2"]["x"] = "front"
        with open(path, "w") as f:
            json.dump(sensors, f)
    elif kind == "missing_h5":
        os.remove(os.path.join(seq_dir, "radar_data.h5"))
    if kind == "truncated":
        path = os.path.join(seq_dir, "radar_data.h5")
        size = os.path.getsize(path)
        with open(path, "r+b") as f:
            f.truncate(size // 2)
    elif kind == "not_json":
        with open(os.path.join(seq_dir, "scenes.json"), "w") as f:
            f.write("{\"sequence_name\": ")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", required=True, help="dataset root to write")
    ap.add_argument("--duration", type=float, default=6.0, help="[s]")
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--widths", choices=["narrow", "wide"], default="narrow")
    ap.add_argument("--labels", choices=["yes", "none"], default="yes")
    ap.add_argument("--mutate", choices=MUTATIONS)
    a = ap.parse_args()
    seq_dir, radar, odo, scenes = make(a.out, a.duration, a.seed, a.widths, a.labels == "yes")
    if a.mutate:
        mutate(a.mutate, seq_dir, radar, odo, scenes)
    else:
        write(seq_dir, radar, odo, scenes)
    print(seq_dir)


if __name__ == "__main__":
    main()
