"""The discharge rate against the orifice width, fitted to the 2D Beverloo law.

    vibrobed sweep run scenarios/sweeps/beverloo.json --out bev --jobs 2
    vibrobed sweep collect bev
    python examples/beverloo.py bev/points.csv --figure beverloo.png

Reads the sweep's point table (the orifice's edges `floor.orifice.from` and `.to`, the mean
`flow.rate` and its standard error over the seeds) and fits Q = C √g (D − k d)^{3/2}, with D the
orifice's width, d the disks' diameter (1 in the shipped silo) and g = 1, as the straight line
Q^{2/3} = C^{2/3} (D − k d) weighted by the rates' errors, over the widths from --min-width up
(narrow orifices clog intermittently). Prints the table and C and k with their errors (scaled by
√(χ²/dof) when the points scatter more than their errors say).
"""

import argparse
import csv

import numpy as np


def read(path):
    rows = list(csv.DictReader(open(path)))
    width = np.array([float(r["floor.orifice.to"]) - float(r["floor.orifice.from"]) for r in rows])
    rate = np.array([float(r["flow.rate:mean"]) for r in rows])
    error = np.array([float(r["flow.rate:se"] or "nan") for r in rows])
    order = np.argsort(width)
    return width[order], rate[order], error[order]


def fit(width, rate, error):
    """Weighted straight line y = a + b D through y = Q^(2/3); C = b^(3/2), k = -a/b."""
    y = rate ** (2 / 3)
    sy = (2 / 3) * rate ** (-1 / 3) * error
    w = 1 / sy**2
    A = np.vstack([np.ones_like(width), width]).T
    cov = np.linalg.inv(A.T @ (A * w[:, None]))
    a, b = cov @ (A.T @ (w * y))
    chi2 = float(np.sum(w * (y - a - b * width) ** 2))
    dof = len(width) - 2
    scale = max(1.0, np.sqrt(chi2 / dof)) if dof > 0 else 1.0
    cov = cov * scale**2
    c, k = b**1.5, -a / b
    # Errors by the delta method.
    gc = np.array([0.0, 1.5 * b**0.5])
    gk = np.array([-1 / b, a / b**2])
    return c, float(np.sqrt(gc @ cov @ gc)), k, float(np.sqrt(gk @ cov @ gk)), chi2, dof


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("points", help="the sweep's points.csv")
    ap.add_argument("--min-width", type=float, default=3.0, help="fit widths from this up (default 3)")
    ap.add_argument("--figure", help="write a figure of Q against D with the fit")
    args = ap.parse_args()
    width, rate, error = read(args.points)
    print(f"{'D':>6} {'rate':>8} {'±':>6}")
    for d, q, e in zip(width, rate, error):
        print(f"{d:6.2f} {q:8.3f} {e:6.3f}")
    used = width >= args.min_width - 1e-9  # widths are differences of edges: round-off
    c, c_err, k, k_err, chi2, dof = fit(width[used], rate[used], error[used])
    print(f"Q = C (D - k)^(3/2) over D >= {args.min_width:g}: C = {c:.3f} ± {c_err:.3f}, "
          f"k = {k:.2f} ± {k_err:.2f} (chi2 = {chi2:.1f} for {dof} dof; errors scaled "
          f"by {max(1.0, (chi2 / dof) ** 0.5) if dof > 0 else 1.0:.2f})")
    if args.figure:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4.2))
        ax.errorbar(width, rate, yerr=error, fmt="o", label="mean over the seeds ± s.e.")
        d = np.linspace(max(k, 0) + 1e-3, width.max() * 1.05, 200)
        ax.plot(d, c * (d - k) ** 1.5, label=f"C (D − k)^3/2: C = {c:.2f}, k = {k:.2f}")
        ax.set_xlabel("orifice width D (diameters)")
        ax.set_ylabel("discharge rate Q (disks per unit time)")
        ax.set_title("silo discharge against the orifice width")
        ax.legend()
        fig.tight_layout()
        fig.savefig(args.figure, dpi=110)
        print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
