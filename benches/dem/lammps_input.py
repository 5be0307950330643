"""The LAMMPS side of a scene: soft disks (Hookean spring and dashpot, GRANULAR package) with
the hard disks' radii, masses and initial state, the sine floor as a wiggling granular wall,
gravity, and a damping that gives the scene's normal restitution at the chosen stiffness."""

import math

# Tangential stiffness over normal stiffness (LAMMPS's default for a null Kt).
KT_OVER_KN = 2.0 / 7.0
# Steps per contact: dt is at most the shortest contact time over this.
STEPS_PER_CONTACT = 25


def damping(e, kn, m_eff):
    """γ_n of the dashpot `m_eff γ_n v_n` that makes the normal restitution e for a contact
    of reduced mass m_eff at stiffness kn: e = exp(−γ_n t_c / 2),
    t_c = π / √(kn/m_eff − γ_n²/4)."""
    if e >= 1.0:
        return 0.0
    log_e = math.log(e)
    return -2.0 * log_e * math.sqrt(kn / m_eff) / math.sqrt(math.pi**2 + log_e**2)


def contact_time(kn, m_eff, gamma):
    """Duration of a damped Hookean contact."""
    return math.pi / math.sqrt(kn / m_eff - gamma**2 / 4.0)


class Model:
    """The contact law at stiffness kn: dampings for pairs (m_eff = m/2 of the lightest disk)
    and for the floor and walls (m_eff = m), the step and the steps between samples."""

    def __init__(self, scene, kn, m_min):
        self.kn = kn
        self.kt = KT_OVER_KN * kn
        self.gamma_pair = damping(scene.e_pair, kn, m_min / 2.0)
        self.gamma_floor = damping(scene.e_floor, kn, m_min)
        self.gamma_wall = damping(scene.e_wall, kn, m_min)
        t_c = contact_time(kn, m_min / 2.0, self.gamma_pair)
        # The step divides the sample interval, so that samples fall on steps.
        self.steps_per_sample = math.ceil(scene.sample_interval * STEPS_PER_CONTACT / t_c)
        self.dt = scene.sample_interval / self.steps_per_sample
        self.contact_time = t_c


def data_file(scene, disks, masses):
    """The `read_data` file: box, one sphere per disk (diameter, density giving its mass with
    LAMMPS's m = 4/3 π r³ ρ), its velocity and spin."""
    a_max = max(d[3] for d in disks)
    ylo = scene.floor_bottom() - 2.0 * a_max
    yhi = scene.lid if scene.lid is not None else max(d[2] for d in disks) + 2.0 * a_max
    lines = [
        "vibrobed scene for benches/dem.sh",
        "",
        f"{len(disks)} atoms",
        "1 atom types",
        "",
        f"0 {scene.width!r} xlo xhi",
        f"{ylo!r} {yhi!r} ylo yhi",
        "-0.5 0.5 zlo zhi",
        "",
        "Atoms # sphere",
        "",
    ]
    for i, ((_, x, y, a, _, _, _), m) in enumerate(zip(disks, masses), 1):
        rho = m / (4.0 / 3.0 * math.pi * a**3)
        lines.append(f"{i} 1 {2 * a!r} {rho!r} {x!r} {y!r} 0")
    lines += ["", "Velocities", ""]
    for i, (_, _, _, _, vx, vy, w) in enumerate(disks, 1):
        lines.append(f"{i} {vx!r} {vy!r} 0 0 0 {w!r}")
    return "\n".join(lines) + "\n"


def contact_args(model, kn_gamma, mu):
    """`Kn Kt γ_n γ_t μ dampflag` of a granular pair or wall style; γ_t = γ_n/2 where rough."""
    gamma_t = kn_gamma / 2.0 if mu else 0.0
    return f"{model.kn!r} {model.kt!r} {kn_gamma!r} {gamma_t!r} {mu or 0.0!r} 1"


def wiggling_floor(scene, model, style, floor):
    """The sine floor h(t) = A sin(ωt): LAMMPS's wiggle moves a wall at `lo` to
    lo + A − A cos(ω s), s the steps since the fix was defined times dt; so lo = −A, and the
    clock is put a quarter period on after the fix is defined (to the nearest step), on a
    multiple of the steps between samples so that the dumps fall on the samples."""
    period = 2.0 * math.pi / scene.omega
    quarter = round(period / 4.0 / model.dt)
    before = -quarter % model.steps_per_sample
    return [
        f"reset_timestep {before}",
        f"fix floor all wall/gran {style} {floor} yplane {-scene.amplitude!r} NULL "
        f"wiggle y {scene.amplitude!r} {period!r}",
        f"reset_timestep {before + quarter}",
    ]


def input_script(scene, model, a_max, dump_path, samples_from_step, total_steps):
    """The LAMMPS input: 2D disks, the contact law, the floor (and walls, lid), gravity,
    velocity Verlet for spheres as discs, a run to the first sample, then samples dumped."""
    style = "hooke/history" if scene.rough else "hooke"
    x_bound = "p" if scene.periodic else "f"
    skin = 0.4 * a_max
    lines = [
        "# written by benches/dem.sh",
        "dimension 2",
        "units lj",
        "atom_style sphere",
        "atom_modify map array",
        f"boundary {x_bound} m p",
        "newton off",
        "comm_modify vel yes",
        "read_data data.lmp",
        f"neighbor {skin!r} bin",
        "neigh_modify delay 0 every 1 check yes",
        f"pair_style gran/{style} {contact_args(model, model.gamma_pair, scene.mu_pair)}",
        "pair_coeff * *",
        f"timestep {model.dt!r}",
        "fix move all nve/sphere disc",
        f"fix gravity all gravity {scene.g!r} vector 0 -1 0",
    ]
    floor = contact_args(model, model.gamma_floor, scene.mu_floor)
    if scene.omega is None:
        lines.append(f"fix floor all wall/gran {style} {floor} yplane 0.0 NULL")
    else:
        lines += wiggling_floor(scene, model, style, floor)
    wall = contact_args(model, model.gamma_wall, scene.mu_wall)
    if not scene.periodic:
        lines.append(f"fix walls all wall/gran {style} {wall} xplane 0.0 {scene.width!r}")
    if scene.lid is not None:
        lines.append(f"fix lid all wall/gran {style} {wall} yplane NULL {scene.lid!r}")
    lines += [
        "fix plane all enforce2d",
        "thermo 100000",
        f"run {samples_from_step}",
        f"dump samples all custom {model.steps_per_sample} {dump_path} id mass x y vx vy omegaz",
        "dump_modify samples sort id format float %.17g",
        f"run {total_steps - samples_from_step}",
    ]
    return "\n".join(lines) + "\n"
