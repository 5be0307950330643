"""A vibrobed scenario as the DEM side needs it: the file with its `--set` overrides applied,
the floor, boundaries, restitutions and frictions it states, and each disk's initial state and
mass from vibrobed's own frame at t = 0 (so both codes start from the same disks)."""

import json
import math


class Refused(Exception):
    """A scenario or option the DEM side cannot map: the message names the field."""


def apply_set(tree, assignment):
    """`KEY=VALUE` as `vibrobed --set` reads it: a dotted path (list entries by index), the
    value read as JSON when it parses, else as a string; `null` removes the field."""
    if "=" not in assignment:
        raise Refused(f"--set {assignment}: expected KEY=VALUE")
    key, text = assignment.split("=", 1)
    try:
        value = json.loads(text)
    except ValueError:
        value = text
    parts = key.split(".")
    node = tree
    for part in parts[:-1]:
        if isinstance(node, list):
            node = node[int(part)]
        else:
            node = node.setdefault(part, {})
    last = parts[-1]
    if isinstance(node, list):
        node[int(last)] = value
    elif value is None:
        node.pop(last, None)
    else:
        node[last] = value


def resolved(path, sets):
    """The scenario file with the overrides applied, in order."""
    with open(path, encoding="utf-8-sig") as f:
        tree = json.load(f)
    for s in sets:
        apply_set(tree, s)
    return tree


class Scene:
    """What the LAMMPS input needs from a resolved scenario (already checked by `vibrobed
    check`): refuses with the field's name what it cannot map."""

    def __init__(self, tree):
        self.tree = tree
        domain, floor = tree["domain"], tree.get("floor")
        self.g = tree.get("gravity")
        if not self.g or floor is None:
            raise Refused("gravity, floor: the DEM side compares beds on a floor under gravity")
        if domain.get("y_boundary", "open") == "periodic":
            raise Refused("domain.y_boundary: periodic is not a bed on a floor")
        for field in ("inlets",):
            if tree.get(field):
                raise Refused(f"{field}: disks entering are not mapped to LAMMPS")
        if domain.get("exit_height") is not None or floor.get("orifice") is not None:
            raise Refused("domain.exit_height, floor.orifice: disks leaving are not mapped")
        if floor.get("waveform", "sine") != "sine":
            raise Refused("floor.waveform: LAMMPS's wiggling wall is a sine")
        if floor.get("phase", 0.0) != 0.0:
            raise Refused("floor.phase: LAMMPS's wiggling wall starts at phase 0")
        self.width = domain["width"]
        self.periodic = domain.get("x_boundary", "walls") == "periodic"
        self.lid = domain.get("height") if domain.get("y_boundary") == "lid" else None
        self.omega = 2 * math.pi * floor["frequency"] if "frequency" in floor else None
        if floor.get("gamma") is not None:
            self.amplitude = floor["gamma"] * self.g / self.omega**2
        else:
            self.amplitude = floor.get("amplitude", 0.0)
        if self.amplitude == 0.0:
            self.omega = None
        coll = tree.get("collisions", {})
        self.e_pair = coll.get("restitution", 1.0)
        self.e_floor = floor.get("restitution", 1.0)
        self.e_wall = domain.get("wall_restitution", 1.0)
        for field, e in (
            ("collisions.restitution", self.e_pair),
            ("floor.restitution", self.e_floor),
            ("domain.wall_restitution", self.e_wall),
        ):
            if e <= 0.0:
                raise Refused(f"{field}: 0 needs an infinite dashpot in LAMMPS")
        self.mu_pair = coll.get("friction")
        self.mu_floor = floor.get("friction")
        self.mu_wall = domain.get("wall_friction")
        self.rough = any(
            x is not None
            for x in (
                self.mu_pair,
                self.mu_floor,
                self.mu_wall,
                coll.get("tangential_restitution"),
                floor.get("tangential_restitution"),
                domain.get("wall_tangential_restitution"),
            )
        )
        q = tree["particles"].get("inertia_factor", 0.5)
        if self.rough and q != 0.5:
            raise Refused("particles.inertia_factor: LAMMPS's disc has I = m a²/2 (q = 0.5)")
        run = tree["run"]
        self.duration = run["duration"]
        self.warmup = run.get("warmup", 0.0)
        out = tree.get("output", {})
        frame = out.get("frame_interval", self.duration / 200.0)
        self.sample_interval = out.get("sample_interval", frame)

    def floor_bottom(self):
        """The floor's lowest point: the profiles' bottom."""
        return -self.amplitude

    def masses(self, radii, species):
        """Each disk's mass as vibrobed sets it: its species' mass, else ρπa², else the
        particles' mass, else equal areal density with the smallest radius of the law of
        mass 1."""
        p = self.tree["particles"]
        law = p["radius"]
        listed = law.get("species") if isinstance(law, dict) else None
        if isinstance(law, dict) and "min" in law:
            a_min = law["min"]
        elif listed:
            a_min = min(s["radius"] for s in listed)
        else:
            a_min = law
        out = []
        for a, k in zip(radii, species):
            own = listed[k].get("mass") if listed else None
            if own is not None:
                out.append(own)
            elif p.get("density") is not None:
                out.append(p["density"] * math.pi * a * a)
            elif p.get("mass") is not None:
                out.append(p["mass"])
            else:
                out.append((a / a_min) ** 2)
        return out


def first_frame(path):
    """The first frame of a vibrobed extended-XYZ trajectory: per disk `(species, x, y, radius,
    vx, vy, omega)` (omega 0 for smooth disks)."""
    with open(path) as f:
        n = int(f.readline())
        header = f.readline()
        props = header.split("Properties=")[1].split()[0].split(":")
        columns, at = {}, 0
        for name, _kind, width in zip(props[0::3], props[1::3], props[2::3]):
            columns[name] = at
            at += int(width)
        disks = []
        for _ in range(n):
            w = f.readline().split()
            species = element_number(w[columns["species"]]) - 1
            x, y = float(w[columns["pos"]]), float(w[columns["pos"] + 1])
            vx, vy = float(w[columns["velo"]]), float(w[columns["velo"] + 1])
            omega = float(w[columns["omega"]]) if "omega" in columns else 0.0
            disks.append((species, x, y, float(w[columns["radius"]]), vx, vy, omega))
    return disks


ELEMENTS = (
    "H He Li Be B C N O F Ne Na Mg Al Si P S Cl Ar K Ca Sc Ti V Cr Mn Fe Co Ni Cu Zn Ga Ge As "
    "Se Br Kr Rb Sr Y Zr Nb Mo Tc Ru Rh Pd Ag Cd In Sn Sb Te I Xe Cs Ba La Ce Pr Nd Pm Sm Eu Gd "
    "Tb Dy Ho Er Tm Yb Lu Hf Ta W Re Os Ir Pt Au Hg Tl Pb Bi Po At Rn Fr Ra Ac Th Pa U Np Pu Am "
    "Cm Bk Cf Es Fm Md No Lr Rf Db Sg Bh Hs Mt Ds Rg Cn Nh Fl Mc Lv Ts Og"
).split()


def element_number(symbol):
    """Atomic number of the species symbol vibrobed writes (species k as element k + 1)."""
    return ELEMENTS.index(symbol) + 1
