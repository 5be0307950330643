"""The bed's motion within one floor period, from the summary's `phase` table.

    vibrobed run scenarios/vibrated_bed.json --summary bed.json
    python examples/phase.py bed.json --figure phase.png

Top: the floor's height, the bed's lower edge (height above the floor below which 5 % of the
disks' bottoms lie) added to the floor's height, and the centre of mass, each at the start of
the phase bins, over two periods; the theoretical take-off of a bed resting on a sine floor
(where the floor's acceleration first falls below −g: sin 2πφ = 1/Γ) is marked. Bottom: the
pressure on the floor in each bin (vertical momentum the floor gives per unit time and width).
"""

import argparse
import json
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("summary")
    ap.add_argument("--figure", default="phase.png")
    args = ap.parse_args()
    s = json.load(open(args.summary))
    p = s["phase"]
    gamma = s["state"]["indicators"]["gamma"]
    bins = len(p["phase"])
    width = 1.0 / bins
    # Two periods, so that the flight and the landing read across the period's end.
    phase = [k + f for k in (0, 1) for f in p["phase"]]
    rep = lambda key: p[key] * 2  # noqa: E731
    floor, lower, com = rep("floor_height"), rep("lower_edge"), rep("com_height")
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6.4), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 2]})
    top.plot(phase, floor, "k-", label="floor h(φ)")
    top.plot(phase, [h + e for h, e in zip(floor, lower)], "o-", color="tab:blue",
             label="bed's lower edge (5 % of the bottoms below)")
    top.set_ylabel("height (d)")
    twin = top.twinx()
    twin.plot(phase, com, "s-", color="tab:red", label="centre of mass")
    twin.set_ylabel("centre of mass (d)", color="tab:red")
    if gamma > 1:
        take_off = math.asin(1 / gamma) / (2 * math.pi)
        for k in (0, 1):
            top.axvline(k + take_off, color="gray", ls="--")
        top.text(take_off + 0.01, min(floor), "take-off of a resting bed: sin 2πφ = 1/Γ",
                 fontsize=8, color="gray")
    lines = top.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    top.legend(lines[0] + more[0], lines[1] + more[1], fontsize=8, loc="upper right")
    top.set_title(f"{s['scenario']}: Γ = {gamma:.3g}, state {s['state']['name']}, "
                  f"{sum(p['samples'])} phase samples", fontsize=10)
    bottom.bar([x + width / 2 for x in phase], rep("pressure"), width=width * 0.9,
               color="tab:green")
    weight = s["floor_pressure"]["weight"]
    bottom.axhline(weight, color="k", ls=":", label=f"weight per width M g / W = {weight:.3g}")
    bottom.set_ylabel("floor pressure in the bin")
    bottom.set_xlabel("floor phase φ (periods; 0: floor at mid-height moving up)")
    bottom.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.figure, dpi=110)
    print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
