"""vibrobed's summary observables measured on LAMMPS's dumped samples, with the definitions
of src/measure/: the centre of mass height (mass-weighted), the granular temperature per axis
Σ m (v − V)² / N about the mass-weighted mean velocity, the rotational temperature
Σ I ω² / N, and the density profile (disk centres per unit area in equal height bins),
averaged over the samples."""


class Bins:
    """Equal height bins from `bottom` to `top` across `width` (vibrobed's profile bins)."""

    def __init__(self, bottom, top, count, width):
        self.bottom, self.top, self.count, self.width = bottom, top, count, width

    @staticmethod
    def of_summary(summary, width):
        """The bins of a vibrobed summary's profiles (from their centres)."""
        centres = summary["profiles"]["height"]
        h = centres[1] - centres[0] if len(centres) > 1 else 2.0 * centres[0]
        bottom = centres[0] - h / 2.0
        return Bins(bottom, bottom + h * len(centres), len(centres), width)


def samples(dump_path):
    """The dump's samples in turn: lists of `(id, mass, x, y, vx, vy, omega)`, sorted by id."""
    with open(dump_path) as f:
        while True:
            line = f.readline()
            if not line:
                return
            if not line.startswith("ITEM: TIMESTEP"):
                continue
            f.readline()
            f.readline()
            n = int(f.readline())
            for _ in range(4):
                f.readline()
            header = f.readline().split()[2:]
            col = {name: k for k, name in enumerate(header)}
            rows = []
            for _ in range(n):
                w = f.readline().split()
                rows.append(
                    (
                        int(w[col["id"]]),
                        float(w[col["mass"]]),
                        float(w[col["x"]]),
                        float(w[col["y"]]),
                        float(w[col["vx"]]),
                        float(w[col["vy"]]),
                        float(w[col["omegaz"]]),
                    )
                )
            yield rows


def measure(dump_path, bins, masses, radii, rough):
    """The averages over the dump's samples; checks that LAMMPS holds vibrobed's masses."""
    h = (bins.top - bins.bottom) / bins.count
    count = [0.0] * bins.count
    com = tx = ty = trot = 0.0
    n_samples = 0
    for rows in samples(dump_path):
        n_samples += 1
        if n_samples == 1:
            for i, (_, m, *_rest) in enumerate(rows):
                if abs(m - masses[i]) > 1e-9 * masses[i]:
                    raise RuntimeError(f"LAMMPS holds mass {m} for disk {i}, vibrobed {masses[i]}")
        m_sum = sum(r[1] for r in rows)
        ux = sum(r[1] * r[4] for r in rows) / m_sum
        uy = sum(r[1] * r[5] for r in rows) / m_sum
        n = len(rows)
        com += sum(r[1] * r[3] for r in rows) / m_sum
        tx += sum(r[1] * (r[4] - ux) ** 2 for r in rows) / n
        ty += sum(r[1] * (r[5] - uy) ** 2 for r in rows) / n
        trot += sum(0.5 * r[1] * radii[i] ** 2 * r[6] ** 2 for i, r in enumerate(rows)) / n
        for r in rows:
            k = (r[3] - bins.bottom) / h
            if k < bins.count:
                count[max(int(k // 1), 0)] += 1.0
    if n_samples == 0:
        raise RuntimeError(f"{dump_path}: no samples")
    s = float(n_samples)
    out = {
        "samples": n_samples,
        "com_height": com / s,
        "temperature": (tx + ty) / (2.0 * s),
        "temperature_x": tx / s,
        "temperature_y": ty / s,
        "density": [c / (s * h * bins.width) for c in count],
    }
    if rough:
        out["temperature_rotational"] = trot / s
    return out


def of_vibrobed(summary):
    """The same observables from a vibrobed summary."""
    t = summary["temperature"]
    out = {
        "samples": summary["engine"]["samples"],
        "com_height": summary["com_height"],
        "temperature": t["mean"],
        "temperature_x": t["x"],
        "temperature_y": t["y"],
        "density": summary["profiles"]["density"],
    }
    if "rotational" in t:
        out["temperature_rotational"] = t["rotational"]
    return out
