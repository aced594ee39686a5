#!/usr/bin/env python3
"""Writes a small nuScenes-layout dataset from the public schema (nutonomy/nuscenes-devkit,
docs/schema_nuscenes.md, and RadarPointCloud.from_file's PCD v0.7 layout), with numpy and json
only: not through dualgrid's writer.

The scene 'scene-test': the ego drives straight at 8 m/s along heading 0.4 rad (global frame); a
lead car drives 12 m/s in the ego's lane, starting 15 m ahead; a crossing car drives 7 m/s across
the road 45 m ahead (left to right); a parked car stands 25 m ahead, 4.5 m to the right; rows of
static reflectors line the road; a pedestrian stands by the road (not a vehicle: never scored);
a car annotated only once (skipped: too few annotations). Five radars at nuScenes-like mounts
scan at ~13 Hz each, staggered; PCD fields as the devkit documents them (float32 positions and
velocities, vx_comp/vy_comp the compensated radial velocity as a vector along the line of
sight, vx/vy the velocity relative to the radar); a few points are invalid (invalid_state 1,
with a wrong velocity) for the devkit's default filter to remove. Samples (key frames) at 2 Hz.

--mutate KIND writes a broken variant (tests/hostile): see MUTATIONS.
Prints the truth as JSON (instance tokens and their velocities) for the checks.
"""
import argparse
import json
import os

import numpy as np

T0 = 1_533_151_600_000_000  # microseconds
EGO_SPEED, HEADING = 8.0, 0.4
EGO_START = np.array([300.0, 200.0])  # the rear axle at t = 0
A = 1.385  # rear axle to box centre (the reader's default for nuScenes' ego)
CHANNELS = {  # channel: (x, y, yaw) in the ego frame (rear axle), nuScenes-like
    "RADAR_FRONT": (3.41, 0.0, 0.0),
    "RADAR_FRONT_LEFT": (2.42, 0.80, 1.54),
    "RADAR_FRONT_RIGHT": (2.42, -0.80, -1.54),
    "RADAR_BACK_LEFT": (-0.56, 0.62, 3.08),
    "RADAR_BACK_RIGHT": (-0.56, -0.62, -3.09),
}
FOV = np.radians(60.0)
FIELDS = [("x", "F", 4), ("y", "F", 4), ("z", "F", 4), ("dyn_prop", "I", 1), ("id", "I", 2),
          ("rcs", "F", 4), ("vx", "F", 4), ("vy", "F", 4), ("vx_comp", "F", 4),
          ("vy_comp", "F", 4), ("is_quality_valid", "I", 1), ("ambig_state", "I", 1),
          ("x_rms", "I", 1), ("y_rms", "I", 1), ("invalid_state", "I", 1), ("pdh0", "I", 1),
          ("vx_rms", "I", 1), ("vy_rms", "I", 1)]
DTYPE = np.dtype([(n, {("F", 4): "<f4", ("I", 1): "i1", ("I", 2): "<i2"}[(t, s)])
                  for n, t, s in FIELDS])
MUTATIONS = ["missing_table", "dangling_token", "pcd_header", "pcd_short", "nan_field",
             "unknown_channel"]

D = np.array([np.cos(HEADING), np.sin(HEADING)])
LEFT = np.array([-np.sin(HEADING), np.cos(HEADING)])


def rot(a):
    return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])


def quat(yaw):
    return [float(np.cos(yaw / 2)), 0.0, 0.0, float(np.sin(yaw / 2))]


def ego_axle(t):
    return EGO_START + EGO_SPEED * t * D


# Objects: token -> (category, centre(t), yaw, velocity, length, width, annotated sample indices)
def objects(duration):
    lead0 = EGO_START + (A + 15.0) * D
    cross_line = EGO_START + 45.0 * D
    parked = EGO_START + 25.0 * D - 4.5 * LEFT
    return {
        "inst-lead": ("vehicle.car", lambda t: lead0 + 12.0 * t * D, HEADING, 12.0 * D, 4.5, 1.8),
        "inst-cross": ("vehicle.car", lambda t: cross_line + (25.0 - 7.0 * t) * LEFT,
                       HEADING - np.pi / 2, -7.0 * LEFT, 4.6, 1.9),
        "inst-parked": ("vehicle.car", lambda t: parked, HEADING, np.zeros(2), 4.4, 1.8),
        "inst-ped": ("human.pedestrian.adult", lambda t: EGO_START + 30.0 * D + 7.0 * LEFT,
                     0.0, np.zeros(2), 0.6, 0.6),
        "inst-once": ("vehicle.car", lambda t: EGO_START + 60.0 * D - 8.0 * LEFT, HEADING,
                      np.zeros(2), 4.5, 1.8),
    }


def box_points(centre, yaw, length, width, sensor, rng):
    """A few points on the faces of the box turned towards the sensor."""
    pts = []
    for sx, sy, nx, ny, span in ((0.5, 0, 1, 0, width), (-0.5, 0, -1, 0, width),
                                 (0, 0.5, 0, 1, length), (0, -0.5, 0, -1, length)):
        n = rot(yaw) @ np.array([nx, ny])
        mid = centre + rot(yaw) @ np.array([sx * length, sy * width])
        if n @ (sensor - mid) <= 0:
            continue
        along = rot(yaw) @ np.array([ny, -nx]) if nx == 0 else rot(yaw) @ np.array([0, 1])
        for _ in range(rng.integers(2, 4)):
            pts.append(mid + along * rng.uniform(-0.45, 0.45) * span)
    return pts


def scan_points(t, channel, objs, statics, rng):
    ax, ay, ayaw = CHANNELS[channel]
    rear = ego_axle(t)
    spos = rear + rot(HEADING) @ np.array([ax, ay])
    syaw = HEADING + ayaw
    v_sensor = EGO_SPEED * D
    rows = []

    def add(p, vel, invalid=0):
        rel = rot(syaw).T @ (p - spos)
        r = np.hypot(*rel)
        if r > 90.0 or r < 1.0 or abs(np.arctan2(rel[1], rel[0])) > FOV:
            return
        u_s = rel / r  # line of sight, sensor frame
        u = (p - spos) / r
        vr_comp = float(vel @ u) + rng.normal(0, 0.05)
        vr = vr_comp - float(v_sensor @ u)
        # vx, vy: relative to the radar, not only along the line of sight (as in the data set)
        tang = np.array([-u_s[1], u_s[0]]) * rng.normal(0, 0.3)
        row = np.zeros(1, DTYPE)
        row["x"], row["y"], row["z"] = rel[0], rel[1], rng.normal(0.5, 0.1)
        row["dyn_prop"] = 0 if abs(vr_comp) > 0.5 else 1
        row["id"] = len(rows)
        row["rcs"] = rng.uniform(-5, 15)
        row["vx"], row["vy"] = vr * u_s + tang
        row["vx_comp"], row["vy_comp"] = vr_comp * u_s
        row["is_quality_valid"], row["ambig_state"], row["invalid_state"] = 1, 3, invalid
        row["pdh0"] = 1
        rows.append(row)

    for tok, (cat, centre, yaw, vel, length, width) in objs.items():
        if tok == "inst-once":
            continue
        for p in box_points(centre(t), yaw, length, width, spos, rng):
            add(p + rng.normal(0, 0.05, 2), vel)
    for s in statics:
        if rng.uniform() < 0.25:
            add(s + rng.normal(0, 0.1, 2), np.zeros(2))
    for _ in range(2):  # invalid ghosts with a wrong velocity: the devkit's filter drops them
        ghost = spos + rot(syaw) @ np.array([rng.uniform(5, 40), rng.uniform(-5, 5)])
        add(ghost, rng.uniform(-15, 15, 2), invalid=1)
    return np.concatenate(rows) if rows else np.zeros(0, DTYPE)


def write_pcd(path, pts):
    header = ["# .PCD v0.7 - Point Cloud Data file format", "VERSION 0.7",
              "FIELDS " + " ".join(n for n, _, _ in FIELDS),
              "SIZE " + " ".join(str(s) for _, _, s in FIELDS),
              "TYPE " + " ".join(t for _, t, _ in FIELDS),
              "COUNT " + " ".join("1" for _ in FIELDS),
              f"WIDTH {len(pts)}", "HEIGHT 1", "VIEWPOINT 0 0 0 1 0 0 0", f"POINTS {len(pts)}",
              "DATA binary"]
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode())
        f.write(pts.tobytes())
        f.write(b"\n")


def make(root, version, duration, seed):
    rng = np.random.default_rng(seed)
    vdir = os.path.join(root, version)
    os.makedirs(vdir, exist_ok=True)
    objs = objects(duration)
    statics = [EGO_START + s * D + o * LEFT for s in np.arange(-30, 140, 4.0) for o in (-9.0, 9.0)]
    tables = {k: [] for k in ["attribute", "calibrated_sensor", "category", "ego_pose", "instance",
                              "log", "map", "sample", "sample_annotation", "sample_data",
                              "scene", "sensor", "visibility"]}
    tables["log"].append({"token": "log-1", "logfile": "test", "vehicle": "n008",
                          "date_captured": "2018-08-01", "location": "singapore-onenorth"})
    tables["map"].append({"token": "map-1", "log_tokens": ["log-1"], "category": "semantic_prior",
                          "filename": "maps/none.png"})
    tables["visibility"].append({"token": "4", "level": "v80-100", "description": "80-100%"})
    tables["attribute"].append({"token": "attr-moving", "name": "vehicle.moving",
                                "description": ""})
    for cat in ("vehicle.car", "human.pedestrian.adult"):
        tables["category"].append({"token": "cat-" + cat, "name": cat, "description": ""})
    for ch, (x, y, yaw) in CHANNELS.items():
        tables["sensor"].append({"token": "sensor-" + ch, "channel": ch, "modality": "radar"})
        tables["calibrated_sensor"].append({"token": "cs-" + ch, "sensor_token": "sensor-" + ch,
                                            "translation": [x, y, 0.5], "rotation": quat(yaw),
                                            "camera_intrinsic": []})
    # Samples at 2 Hz.
    n_samples = int(duration * 2) + 1
    sample_t = [T0 + 500_000 * i for i in range(n_samples)]
    for i, ts in enumerate(sample_t):
        tables["sample"].append({"token": f"sample-{i}", "timestamp": ts, "scene_token": "scene-1",
                                 "prev": f"sample-{i - 1}" if i > 0 else "",
                                 "next": f"sample-{i + 1}" if i + 1 < n_samples else ""})
    tables["scene"].append({"token": "scene-1", "name": "scene-test", "description": "a test",
                            "log_token": "log-1", "nbr_samples": n_samples,
                            "first_sample_token": "sample-0",
                            "last_sample_token": f"sample-{n_samples - 1}"})
    # Scans: each radar every ~77 ms (13 Hz), staggered.
    end_us = sample_t[-1] - T0
    for k, ch in enumerate(CHANNELS):
        times = []
        t = 0.011 * k
        while t * 1e6 <= end_us:
            times.append(T0 + int(round(t * 1e6)))
            t += 0.0769 + rng.uniform(-0.002, 0.002)
        keys = {min(range(len(times)), key=lambda j: abs(times[j] - s)): i
                for i, s in enumerate(sample_t)}
        os.makedirs(os.path.join(root, "samples", ch), exist_ok=True)
        os.makedirs(os.path.join(root, "sweeps", ch), exist_ok=True)
        for j, ts in enumerate(times):
            key = j in keys
            sample = keys[j] if key else next((i for i, s in enumerate(sample_t) if s >= ts),
                                              n_samples - 1)
            tok = f"sd-{ch}-{j}"
            name = f"{'samples' if key else 'sweeps'}/{ch}/n008__{ch}__{ts}.pcd"
            write_pcd(os.path.join(root, name), scan_points((ts - T0) / 1e6, ch, objs, statics, rng))
            p = ego_axle((ts - T0) / 1e6)
            tables["ego_pose"].append({"token": tok, "timestamp": ts,
                                       "translation": [float(p[0]), float(p[1]), 0.0],
                                       "rotation": quat(HEADING)})
            tables["sample_data"].append({
                "token": tok, "sample_token": f"sample-{sample}", "ego_pose_token": tok,
                "calibrated_sensor_token": "cs-" + ch, "timestamp": ts, "fileformat": "pcd",
                "is_key_frame": key, "height": 0, "width": 0, "filename": name,
                "prev": f"sd-{ch}-{j - 1}" if j > 0 else "",
                "next": f"sd-{ch}-{j + 1}" if j + 1 < len(times) else ""})
    # Annotations at every sample (inst-once: only the last).
    for tok, (cat, centre, yaw, vel, length, width) in objs.items():
        idx = [n_samples - 1] if tok == "inst-once" else list(range(n_samples))
        ann = [f"ann-{tok}-{i}" for i in idx]
        tables["instance"].append({"token": tok, "category_token": "cat-" + cat,
                                   "nbr_annotations": len(idx), "first_annotation_token": ann[0],
                                   "last_annotation_token": ann[-1]})
        for a, i in enumerate(idx):
            c = centre((sample_t[i] - T0) / 1e6)
            tables["sample_annotation"].append({
                "token": ann[a], "sample_token": f"sample-{i}", "instance_token": tok,
                "visibility_token": "4", "attribute_tokens": [],
                "translation": [float(c[0]), float(c[1]), 0.8], "size": [width, length, 1.6],
                "rotation": quat(yaw), "num_lidar_pts": 0, "num_radar_pts": 0,
                "prev": ann[a - 1] if a > 0 else "", "next": ann[a + 1] if a + 1 < len(ann) else ""})
    for name, rows in tables.items():
        with open(os.path.join(vdir, name + ".json"), "w") as f:
            json.dump(rows, f)
    return {tok: {"category": o[0], "velocity": [float(v) for v in o[3]]}
            for tok, o in objs.items()}


def mutate(kind, root, version):
    vdir = os.path.join(root, version)

    def load(name):
        with open(os.path.join(vdir, name + ".json")) as f:
            return json.load(f)

    def dump(name, rows):
        with open(os.path.join(vdir, name + ".json"), "w") as f:
            json.dump(rows, f)

    sd = load("sample_data")
    some_pcd = os.path.join(root, sd[3]["filename"])
    if kind == "missing_table":
        os.remove(os.path.join(vdir, "ego_pose.json"))
    elif kind == "dangling_token":
        sd[3]["ego_pose_token"] = "nowhere"
        dump("sample_data", sd)
    elif kind == "pcd_header":
        data = open(some_pcd, "rb").read().replace(b"TYPE F F F I", b"TYPE F X F I", 1)
        open(some_pcd, "wb").write(data)
    elif kind == "pcd_short":
        data = open(some_pcd, "rb").read()
        open(some_pcd, "wb").write(data[:-20])
    elif kind == "nan_field":
        data = bytearray(open(some_pcd, "rb").read())
        start = data.index(b"DATA binary\n") + len(b"DATA binary\n")
        off = start + DTYPE.itemsize + DTYPE.fields["vx_comp"][1]  # point 1's vx_comp
        data[off:off + 4] = np.array([np.nan], "<f4").tobytes()
        open(some_pcd, "wb").write(bytes(data))
    elif kind == "unknown_channel":
        s = load("sensor")
        s[1]["channel"] = "RADAR_TOP"
        dump("sensor", s)
    else:
        raise SystemExit(f"unknown mutation {kind}")


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--out", required=True)
    ap.add_argument("--version", default="v1.0-mini")
    ap.add_argument("--duration", type=float, default=8.0)
    ap.add_argument("--seed", type=int, default=7)
    ap.add_argument("--mutate", choices=MUTATIONS)
    a = ap.parse_args()
    truth = make(a.out, a.version, a.duration, a.seed)
    if a.mutate:
        mutate(a.mutate, a.out, a.version)
    print(json.dumps(truth))


if __name__ == "__main__":
    main()
