"""The mean flow of a vibrated bed between walls, from the 2D fields of `vibrobed run --fields`:
convection rolls, measured.

    vibrobed run scenarios/convection.json --set output.field_bins=[20,20] --fields rough.csv
    vibrobed run scenarios/convection.json --set output.field_bins=[20,20] \\
        --set domain.wall_friction=0 --fields smooth.csv
    python examples/convection.py rough.csv smooth.csv --figure convection.png

For each fields file (time-averaged after the run's warm-up): the mean vertical velocity of the
disks in the strips along the walls (the outer 15 % of the width on each side) and in the centre
(the middle 30 %), and the circulation, centre minus walls (the bed's ride up and down with the
floor is common to both and cancels). A strip's mean is its cells' mean velocities weighted by
their number densities: with disks of one mass, exactly the mean v_y of every disk seen in the
strip at every sample. Choose the grid so that the strips' edges are cell edges (20 columns on a
width of 30: 3 columns per wall strip, 6 in the centre). Also: the circulation of the mean
velocity around the left roll, ∮ u · dl over the cells' centres of the left half of the bed.
With --figure, the fields, one panel per file: packing fraction as a heat map, mean velocity as
arrows. Needs pandas, numpy and matplotlib: examples/requirements.txt.
"""

import argparse

import numpy as np
import pandas as pd

WALL, CENTRE = 0.15, (0.35, 0.65)


def read(path):
    """The fields as 2D arrays (rows: height), with the cells' centres."""
    f = pd.read_csv(path)
    grid = {q: f.pivot(index="y", columns="x", values=q) for q in f.columns if q not in "ijxy"}
    xs, ys = grid["number_density"].columns.to_numpy(), grid["number_density"].index.to_numpy()
    return xs, ys, {q: g.to_numpy() for q, g in grid.items()}


def strip_mean(xs, fields, inside):
    """Mean v_y of the disks in the columns whose centres satisfy `inside` (fraction of width)."""
    width = xs[-1] + xs[0]  # centres of equal cells from 0: first + last = width
    cols = inside(xs / width)
    n = fields["number_density"][:, cols]
    vy = np.nan_to_num(fields["velocity_y"][:, cols])
    return (n * vy).sum() / n.sum()


def loop_circulation(xs, ys, fields):
    """∮ u · dl anticlockwise around the cells' centres of the left half of the bed, over the
    rows that hold disks on average in every cell of the half (the bed, not the dilute sky)."""
    half = xs < 0.5 * (xs[-1] + xs[0])
    n = fields["number_density"][:, half]
    rows = np.where((n > 0.2).all(axis=1))[0]
    ux = np.nan_to_num(fields["velocity_x"][:, half])[rows]
    uy = np.nan_to_num(fields["velocity_y"][:, half])[rows]
    dx, dy = xs[1] - xs[0], ys[1] - ys[0]
    bottom = ux[0].sum() * dx  # rightwards along the lowest row
    right = uy[:, -1].sum() * dy  # up the right edge
    top = -ux[-1].sum() * dx  # leftwards along the top row
    left = -uy[:, 0].sum() * dy  # down the left edge
    return bottom + right + top + left, (ys[rows[0]], ys[rows[-1]])


def report(path):
    xs, ys, fields = read(path)
    walls = strip_mean(xs, fields, lambda u: (u < WALL) | (u > 1 - WALL))
    centre = strip_mean(xs, fields, lambda u: (u > CENTRE[0]) & (u < CENTRE[1]))
    loop, (y0, y1) = loop_circulation(xs, ys, fields)
    print(f"{path}:")
    print(f"  v_y along the walls {walls:+.4f}")
    print(f"  v_y in the centre   {centre:+.4f}")
    print(f"  circulation (centre - walls) {centre - walls:+.4f}")
    print(f"  circulation around the left roll (y {y0:.1f} to {y1:.1f}) {loop:+.3f}")
    return xs, ys, fields, centre - walls


def figure(runs, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(runs), figsize=(5.2 * len(runs), 5.8), squeeze=False)
    top = max(ys[(f["packing_fraction"] > 0.02).any(axis=1)].max() + (ys[1] - ys[0])
              for (xs, ys, f, _), _ in runs)
    for ax, ((xs, ys, fields, r), title) in zip(axes[0], runs):
        dx, dy = xs[1] - xs[0], ys[1] - ys[0]
        phi = fields["packing_fraction"]
        im = ax.pcolormesh(
            np.append(xs - 0.5 * dx, xs[-1] + 0.5 * dx),
            np.append(ys - 0.5 * dy, ys[-1] + 0.5 * dy),
            phi, cmap="Greys", vmin=0.0, vmax=0.9,
        )
        keep = fields["number_density"] > 0.2  # cells holding a disk half the time or more
        X, Y = np.meshgrid(xs, ys)
        ax.quiver(X[keep], Y[keep], fields["velocity_x"][keep], fields["velocity_y"][keep],
                  fields["velocity_y"][keep], cmap="coolwarm", clim=(-0.2, 0.2),
                  scale=2.0, scale_units="width", width=0.006)
        ax.set_title(f"{title}\ncentre − walls: {r:+.3f} √(g d)", fontsize=11)
        ax.set_xlabel("x (disk diameters)")
        ax.set_ylabel("height y (disk diameters)")
        ax.set_aspect("equal")
        ax.set_ylim(ys[0] - 0.5 * dy, top)
    bar = fig.colorbar(im, ax=axes[0].tolist(), shrink=0.8)
    bar.set_label("packing fraction φ; arrows: mean velocity (red up, blue down)")
    fig.savefig(out, dpi=110, bbox_inches="tight")
    print(f"figure: {out}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("fields", nargs="+", help="CSV files written by vibrobed run --fields")
    p.add_argument("--titles", nargs="*", help="panel titles (default: the file names)")
    p.add_argument("--figure", help="write the fields here (PNG)")
    a = p.parse_args()
    titles = a.titles or a.fields
    runs = [(report(f), title) for f, title in zip(a.fields, titles)]
    if a.figure:
        figure(runs, a.figure)


if __name__ == "__main__":
    main()
