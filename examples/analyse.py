"""Read everything `vibrobed run` writes, from Python, and make one figure.

    vibrobed run scenarios/vibrated_bed.json --summary out/summary.json \
        --profiles out/profiles.csv --trajectory out/trajectory.xyz --rrd out/recording.rrd
    python examples/analyse.py out            # writes out/analyse.png

- the summary (JSON) and the time-averaged height profiles (CSV) with pandas;
- the trajectory (extended XYZ) with ASE;
- the recording (.rrd) with rerun-sdk's reader (`rerun.experimental.RrdReader`), as pandas
  tables of the time series and of the live profiles.

It checks that the three agree where they overlap (the centre-of-mass height of the recording
against the mean height of the trajectory's disks, the frame count), so that it fails loudly
when a format changes. Needs examples/requirements.txt; examples/run.sh runs it end to end.
"""

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import ase.io  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import rerun.experimental as rrx  # noqa: E402


def load_summary(path):
    """The summary as a dict, and its event counts as a one-row table."""
    summary = json.loads(Path(path).read_text())
    return summary, pd.DataFrame([summary["events"]])


def load_profiles(path):
    """Time-averaged profiles: one row per height bin."""
    return pd.read_csv(path)


def load_trajectory(path):
    """Per frame: simulated time, floor height, mean disk height (all frames, via ASE)."""
    frames = ase.io.read(path, index=":")
    return pd.DataFrame(
        {
            "time": [a.info["Time"] for a in frames],
            "floor_height": [a.info.get("floor_height", np.nan) for a in frames],
            "mean_height": [a.positions[:, 1].mean() for a in frames],
            "disks": [len(a) for a in frames],
        }
    ), frames


def load_recording(path):
    """The recording's time series (one column per series, indexed by frame) and its live
    packing-fraction profiles (frame, height, value), from the chunks of the .rrd file."""
    series, profiles = [], []
    for chunk in rrx.RrdReader(str(path)).stream().to_chunks():
        entity = chunk.entity_path
        if chunk.is_static:
            continue
        table = chunk.to_record_batch().to_pandas()
        if entity.startswith("/series/"):
            series.append(
                pd.DataFrame(
                    {
                        "frame": table["frame"],
                        "sim_time": table["sim_time"].dt.total_seconds(),
                        "name": entity.removeprefix("/series/"),
                        "value": table["Scalars:scalars"].str[0],
                    }
                )
            )
        elif entity == "/profiles/packing_fraction":
            for frame, strips in zip(table["frame"], table["LineStrips2D:strips"]):
                points = np.array([list(p) for p in strips[0]])
                profiles.append(
                    pd.DataFrame(
                        {"frame": frame, "height": points[:, 1], "value": points[:, 0]}
                    )
                )
    series = pd.concat(series).pivot_table(
        index=["frame", "sim_time"], columns="name", values="value"
    )
    profiles = pd.concat(profiles) if profiles else pd.DataFrame()
    return series.reset_index(), profiles


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir", type=Path, help="folder holding summary.json, profiles.csv, "
                        "trajectory.xyz and recording.rrd")
    parser.add_argument("--plot", type=Path, help="figure to write (default: DIR/analyse.png)")
    args = parser.parse_args()
    d = args.dir

    summary, events = load_summary(d / "summary.json")
    profiles = load_profiles(d / "profiles.csv")
    trajectory, frames = load_trajectory(d / "trajectory.xyz")
    series, live = load_recording(d / "recording.rrd")

    print(f"{summary['scenario']}: {summary['particles']} disks, t = {summary['sim_time']}, "
          f"ending {summary['ending']}")
    print("events:", events.iloc[0].to_dict())
    print(f"trajectory: {len(frames)} frames of {trajectory['disks'].iloc[0]} disks")
    print(f"recording: {len(series)} frames, series {sorted(c for c in series.columns if '/' in c or c == 'com_height')}")

    # The three outputs agree where they overlap.
    assert (trajectory["disks"] == summary["particles"]).all()
    merged = pd.merge_asof(series.sort_values("sim_time"), trajectory.sort_values("time"),
                           left_on="sim_time", right_on="time", tolerance=1e-6)
    merged = merged.dropna(subset=["mean_height"])
    assert len(merged) > 0, "no trajectory frame at a recorded frame's time"
    radii = np.concatenate([a.arrays["radius"] for a in frames[:1]])
    if np.all(radii == radii[0]):  # equal masses: the centre of mass is the mean height
        gap = (merged["com_height"] - merged["mean_height"]).abs().max()
        print(f"centre of mass, recording vs trajectory: largest difference {gap:.2e}")
        assert gap < 1e-6, gap
    top = profiles["height"].max()
    print(f"mean packing fraction below {top:.3g}: {profiles['packing_fraction'].mean():.4f}")

    fig, (ax_phi, ax_com) = plt.subplots(1, 2, figsize=(10, 4))
    ax_phi.plot(profiles["packing_fraction"], profiles["height"], "k-",
                label="time average (profiles.csv)")
    if not live.empty:
        last = live[live["frame"] == live["frame"].max()]
        ax_phi.plot(last["value"], last["height"], "C0-", alpha=0.7,
                    label=f"frame {last['frame'].iloc[0]} (recording)")
    ax_phi.set_xlabel("packing fraction φ (dimensionless)")
    ax_phi.set_ylabel("height (length units of the scenario)")
    ax_phi.legend()
    ax_com.plot(series["sim_time"], series["com_height"], "C1-", label="recording")
    ax_com.plot(trajectory["time"], trajectory["mean_height"], "k.", ms=3, label="trajectory")
    ax_com.set_xlabel("simulated time (time units of the scenario)")
    ax_com.set_ylabel("centre-of-mass height (length units)")
    ax_com.legend()
    fig.suptitle(summary["scenario"])
    fig.tight_layout()
    out = args.plot or d / "analyse.png"
    fig.savefig(out, dpi=100)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
