"""The mean flow of a vibrated bed between walls, from `vibrobed run --trajectory`: convection
rolls, measured.

    vibrobed run scenarios/convection.json --trajectory rough.xyz
    vibrobed run scenarios/convection.json --set domain.wall_friction=0 --trajectory smooth.xyz
    python examples/convection.py rough.xyz smooth.xyz --warmup 50 --figure convection.png

For each trajectory, over the frames after the warm-up: the mean vertical velocity of the disks
in the strips along the walls (the outer 15 % of the width on each side) and in the centre
(the middle 30 %), and the circulation, centre minus walls (the bed's ride up and down with the
floor is common to both and cancels). Frames a fraction of the floor's period apart sample its
phases evenly. Standard errors come from ten consecutive blocks of frames (the flow is
correlated in time).
Rolls with down-flow along the walls and up-flow in the centre give a positive circulation.
With --figure, the time-averaged velocity field on a coarse grid, one panel per trajectory.
Needs numpy (and matplotlib for the figure): examples/requirements.txt.
"""

import argparse

import numpy as np

BLOCKS = 10
WALL, CENTRE = 0.15, (0.35, 0.65)


def read(path, warmup):
    """The frames at or after `warmup`: (width, [x, y, vx, vy] per disk) each."""
    frames = []
    with open(path) as f:
        while line := f.readline():
            n = int(line)
            head = f.readline()
            time = float(head.split("Time=")[1].split()[0])
            width = float(head.split('Lattice="')[1].split()[0])
            rows = [f.readline() for _ in range(n)]
            if time >= warmup:
                # species x y z radius vx vy vz [angle omega]
                frames.append((width, np.loadtxt(rows, usecols=(1, 2, 5, 6), ndmin=2)))
    if not frames:
        raise SystemExit(f"{path}: no frame at or after t = {warmup}")
    return frames


def strips(frames):
    """Mean v_y at the walls and in the centre, per block of frames."""
    walls, centre = [], []
    for block in np.array_split(np.arange(len(frames)), BLOCKS):
        sums = np.zeros(2)
        counts = np.zeros(2)
        for k in block:
            width, d = frames[k]
            x, vy = d[:, 0] / width, d[:, 3]
            for s, m in enumerate([(x < WALL) | (x > 1 - WALL), (x > CENTRE[0]) & (x < CENTRE[1])]):
                sums[s] += vy[m].sum()
                counts[s] += m.sum()
        w, c = sums / counts
        walls.append(w)
        centre.append(c)
    return np.array(walls), np.array(centre)


def mean_and_error(blocks):
    return blocks.mean(), blocks.std(ddof=1) / np.sqrt(len(blocks))


def field(frames, nx=10, ny=10, top=None):
    """The time-averaged velocity on an nx × ny grid up to `top`, and the mean number of disks
    per cell."""
    width = frames[0][0]
    top = top or 2.0 * np.mean([d[:, 1].mean() for _, d in frames])
    sums = np.zeros((3, ny, nx))
    for _, d in frames:
        x, y, vx, vy = d.T
        i = np.clip((x / width * nx).astype(int), 0, nx - 1)
        j = (y / top * ny).astype(int)
        m = (j >= 0) & (j < ny)
        for s, v in enumerate([vx, vy, np.ones_like(vx)]):
            np.add.at(sums[s], (j[m], i[m]), v[m])
    count = np.maximum(sums[2], 1)
    return width, top, sums[0] / count, sums[1] / count, sums[2] / len(frames)


def report(path, warmup):
    frames = read(path, warmup)
    walls, centre = strips(frames)
    (w, dw), (c, dc), (r, dr) = map(mean_and_error, (walls, centre, centre - walls))
    print(f"{path}: {len(frames)} frames from t = {warmup}")
    print(f"  v_y along the walls {w:+.4f} ± {dw:.4f}")
    print(f"  v_y in the centre   {c:+.4f} ± {dc:.4f}")
    print(f"  circulation (centre - walls) {r:+.4f} ± {dr:.4f}")
    return frames, (r, dr)


def figure(runs, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    top = max(2.0 * np.mean([d[:, 1].mean() for _, d in f]) for f, _, _ in runs)
    fig, axes = plt.subplots(1, len(runs), figsize=(5.2 * len(runs), 5.6), squeeze=False)
    vmax = 0.2
    for ax, (frames, (r, dr), title) in zip(axes[0], runs):
        width, top, vx, vy, density = field(frames, top=top)
        nx, ny = vx.shape[1], vx.shape[0]
        xs = (np.arange(nx) + 0.5) * width / nx
        ys = (np.arange(ny) + 0.5) * top / ny
        shown = np.where(density > 0.5, vy, np.nan)  # cells holding disks
        im = ax.pcolormesh(np.linspace(0, width, nx + 1), np.linspace(0, top, ny + 1), shown,
                           cmap="coolwarm", vmin=-vmax, vmax=vmax)
        X, Y = np.meshgrid(xs, ys)
        keep = density > 0.5
        ax.quiver(X[keep], Y[keep], vx[keep], vy[keep], scale=2.0, scale_units="width",
                  width=0.006)
        ax.set_title(f"{title}\ncentre − walls: {r:+.3f} ± {dr:.3f}", fontsize=11)
        ax.set_xlabel("x (disk diameters)")
        ax.set_ylabel("height y (disk diameters)")
        ax.set_aspect("equal")
        ax.set_xlim(0, width)
        ax.set_ylim(0, top)
    bar = fig.colorbar(im, ax=axes[0].tolist(), shrink=0.8)
    bar.set_label("mean v_y (√(g d)); arrows: mean velocity")
    fig.savefig(out, dpi=110, bbox_inches="tight")
    print(f"figure: {out}")


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("trajectories", nargs="+")
    p.add_argument("--warmup", type=float, default=0.0, help="frames before this time are left out")
    p.add_argument("--titles", nargs="*", help="panel titles (default: the file names)")
    p.add_argument("--figure", help="write the mean velocity fields here (PNG)")
    a = p.parse_args()
    titles = a.titles or a.trajectories
    runs = [(*report(t, a.warmup), title) for t, title in zip(a.trajectories, titles)]
    if a.figure:
        figure(runs, a.figure)


if __name__ == "__main__":
    main()
