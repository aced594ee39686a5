"""Scans a highway scene with the radar model into a pandas DataFrame.

The ego drives at 25 m/s along +x on the middle lane of a three-lane road with a guard rail on
each side; a car ahead, a slower truck on the right lane and a faster car behind on the left lane,
about to overtake. One scan of the paper's five-radar rig at t = 0 (every sensor fires) becomes a
DataFrame with one row per detection; the script prints per-sensor counts, a summary and the first
rows of the targets' detections, and the shape of the (N, 6) measurement array the grid takes.

    PYTHONPATH=build/python/site python3 docs/examples/python/radar_scan.py
"""

import math

import pandas as pd

import dualgrid


def main():
    rig = dualgrid.default_rig(4.5, 1.8)  # front_left, front_right, rear_left, rear_right, front
    radar = dualgrid.RadarModel(rig, dualgrid.ModelOptions(), seed=42)
    ego = dualgrid.EgoMotion(pose=(0.0, 0.0, 0.0), velocity=(25.0, 0.0), length=4.5, width=1.8)

    # Targets as a table, one row per vehicle (columns: dualgrid.TARGET_COLUMNS; a column left
    # out takes its default, but every value present must be finite: no NaN holes).
    targets = pd.DataFrame([
        dict(id=1, x=35.0, y=0.0, yaw=0.0, length=4.5, width=1.8, vx=22.0, vy=0.0, rcs_dbsm=10.0),
        dict(id=2, x=18.0, y=-3.5, yaw=0.0, length=12.0, width=2.5, vx=20.0, vy=0.0,
             rcs_dbsm=20.0),
        dict(id=3, x=-20.0, y=3.5, yaw=math.radians(2.0), length=4.5, width=1.8, vx=30.0,
             vy=1.0, rcs_dbsm=10.0),
    ])
    rails = [dict(id=10, points=[[-200.0, -5.5], [200.0, -5.5]]),
             dict(id=11, points=[[-200.0, 5.5], [200.0, 5.5]], rcs_dbsm_per_metre=-5.0)]
    scene = dualgrid.Scene(targets=targets, polylines=rails)

    detections = radar.scan(ego, scene, step=0, time=0.0, step_length=0.05)
    df = pd.DataFrame(detections)
    df["sensor_name"] = [rig[i].name for i in df["sensor"]]
    df["source"] = df["source_id"].map({1: "car", 2: "truck", 3: "car behind", 10: "right rail",
                                        11: "left rail", -1: "clutter"})

    print(f"{len(df)} detections of {df['sensor'].nunique()} sensors ({scene!r})")
    print(df.groupby(["sensor_name", "source"]).size().unstack(fill_value=0))
    print()
    on_targets = df[df["source_id"].isin([1, 2, 3])]
    with pd.option_context("display.width", 120, "display.precision", 2):
        # Compensated radial speed: the target's velocity over ground on the line of sight.
        print(on_targets.groupby("source").agg(
            detections=("x", "size"), nearest_m=("range", "min"),
            radial_speed_over_ground=("radial_speed_compensated", "mean")))
        print()
        print(on_targets[["sensor_name", "source", "range", "azimuth", "range_rate",
                          "radial_speed_compensated", "x", "y", "snr_db"]].head(8)
              .to_string(index=False))

    measurements = dualgrid.detections_to_measurements(detections, ego_box=ego)
    print(f"\nmeasurement array for DynamicGrid.update(): shape {measurements.shape}, columns "
          f"{list(dualgrid.MEASUREMENT_COLUMNS)}")


if __name__ == "__main__":
    main()
