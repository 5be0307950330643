//! Throughput of the event-driven engine: collisions per second on one core.
//!
//! Run everything (about 5 minutes on an idle 2-core box; most of it is setting up and melting
//! the N = 10^6 gas):
//!
//! ```text
//! cargo bench --no-default-features --bench throughput
//! ```
//!
//! or a subset with criterion's name filter (a regular expression on the benchmark id):
//!
//! ```text
//! cargo bench --no-default-features --bench throughput -- gas/2500/
//! cargo bench --no-default-features --bench throughput -- 'bed/1000/'
//! VIBROBED_BENCH_BED=0 cargo bench --no-default-features --bench throughput
//! ```
//!
//! Benchmark ids: `gas/{N}/phi{φ}` (elastic disks of radius 0.5 in a square periodic box) and
//! `bed/{N}/gamma3` (vibrated bed of five layers: g = 1, floor Γ = 3 at frequency 0.5, floor and
//! pair restitution 0.9, periodic in x, open top). Each criterion iteration pops a fixed number K
//! of events (`Simulation::step_events`: collisions, stale predictions, re-mappings), so
//! criterion's throughput is *events*/s. After criterion, a table is printed with what the user
//! wants: real collisions per second (median of R timed repetitions of K events, Δcollisions/Δt),
//! bytes per disk, the neighbour mask, stale events per collision and collisions per grid
//! re-mapping — only for the points the filter selected. For the vibrated bed it also prints the elastic gas rate at the same N and
//! the ratio.
//!
//! Environment: `VIBROBED_BENCH_BED=0` skips the vibrated bed; `VIBROBED_BENCH_REPS` sets R
//! (default 5); `VIBROBED_BENCH_GRID=hashed` puts the gas on Isobe's compressed array instead of
//! the dense grid; `VIBROBED_BENCH_MASK` forces the neighbour mask (`min`, `r3` … `r10`; default
//! `auto`), to compare masks; `VIBROBED_BENCH_REMAP=local` runs every point with the local
//! re-mapping instead of Isobe's global one.

use criterion::{Criterion, SamplingMode, Throughput};
use std::hint::black_box;
use std::time::{Duration, Instant};
use vibrobed::engine::{Scene, Simulation};
use vibrobed::physics::flight::{Ballistic, Flight, Straight};
use vibrobed::scenario::Scenario;

/// Disk radius everywhere.
const RADIUS: f64 = 0.5;
/// Gas sizes and packing fractions (the six required points).
const GAS_N: [usize; 3] = [2_500, 100_000, 1_000_000];
const GAS_PHI: [f64; 2] = [0.3, 0.7];
/// Vibrated-bed sizes.
const BED_N: [usize; 3] = [1_000, 10_000, 100_000];
/// Collisions per disk run before measuring the gas (not timed).
const GAS_MELT_PER_DISK: u64 = 5;

/// Events per criterion iteration (and per timed repetition of the table), K, and the events
/// per second measured on a shared 2-core box when K was chosen: one iteration should take about
/// 0.1–0.5 s (longer at N = 10^6, where K must span at least one grid re-mapping). The expected
/// rate only sets criterion's measurement time (10 iterations), so a faster engine just gets
/// more iterations per sample.
fn plan(kind: Kind, n: usize) -> (u64, f64) {
    match (kind, n) {
        (Kind::Gas(phi), _) if phi < 0.5 && n <= 20_000 => (100_000, 0.25e6),
        (Kind::Gas(_), _) if n <= 20_000 => (300_000, 0.9e6),
        (Kind::Gas(phi), _) if phi < 0.5 && n <= 200_000 => (40_000, 0.07e6),
        (Kind::Gas(_), _) if n <= 200_000 => (200_000, 0.4e6),
        (Kind::Gas(phi), _) if phi < 0.5 => (150_000, 0.13e6),
        (Kind::Gas(_), _) => (300_000, 0.4e6),
        (Kind::Bed, _) if n <= 20_000 => (100_000, 0.4e6),
        (Kind::Bed, _) => (60_000, 0.17e6),
    }
}

fn events_per_iter(kind: Kind, n: usize) -> u64 {
    plan(kind, n).0
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Gas(f64),
    Bed,
}

/// One measured point of the table.
#[derive(Clone)]
struct Row {
    id: String,
    n: usize,
    /// Events per repetition.
    k: u64,
    /// Median collisions per second over the repetitions.
    coll_per_s: f64,
    /// Median events (popped) per second.
    events_per_s: f64,
    bytes_per_disk: f64,
    mask: &'static str,
    /// Stale events per collision over the repetitions.
    stale_ratio: f64,
    /// Collisions per grid re-mapping (DUTC) over the repetitions.
    coll_per_remap: f64,
    /// Fraction of the collisions that were floor impacts (vibrated bed).
    floor_frac: f64,
    /// Simulated time covered by the repetitions (to see how far the bed moved).
    sim_time: f64,
}

/// A set-up engine of either flight law.
enum Engine {
    Gas(Simulation<Straight>),
    Bed(Simulation<Ballistic>),
}

macro_rules! with_sim {
    ($e:expr, $s:ident => $body:expr) => {
        match $e {
            Engine::Gas($s) => $body,
            Engine::Bed($s) => $body,
        }
    };
}

impl Engine {
    fn step(&mut self, k: u64) {
        with_sim!(self, s => s.step_events(k).expect("step_events failed"))
    }
}

/// `engine.mask` of every scene: `VIBROBED_BENCH_MASK` (`min`, `r3` … `r10`), default `auto`.
fn mask_choice() -> String {
    std::env::var("VIBROBED_BENCH_MASK").unwrap_or_else(|_| "auto".to_string())
}

/// `engine.remap` of every scene: `VIBROBED_BENCH_REMAP` (`global`, `local` or `auto`),
/// default `auto` (the engine's default: local for the gas, global for the open-top bed).
fn remap_choice() -> String {
    std::env::var("VIBROBED_BENCH_REMAP").unwrap_or_else(|_| "auto".to_string())
}

/// `engine.grid` of the gas scenes: `VIBROBED_BENCH_GRID` (`dense` or `hashed`), default `auto`
/// (dense for the closed box). The vibrated bed has an open top and is always hashed.
fn grid_choice() -> String {
    std::env::var("VIBROBED_BENCH_GRID").unwrap_or_else(|_| "auto".to_string())
}

/// `engine.queue` of every scene: `VIBROBED_BENCH_QUEUE` (`calendar` or `tree`), default
/// `calendar` (the engine's default).
fn queue_choice() -> String {
    std::env::var("VIBROBED_BENCH_QUEUE").unwrap_or_else(|_| "calendar".to_string())
}

fn gas_scenario(n: usize, phi: f64) -> Scenario {
    let width = (n as f64 * std::f64::consts::PI * RADIUS * RADIUS / phi).sqrt();
    let json = serde_json::json!({
        "name": format!("bench gas N={n} phi={phi}"),
        "seed": 1,
        "domain": { "width": width, "x_boundary": "periodic", "y_boundary": "periodic" },
        "particles": { "count": n, "radius": RADIUS, "packing_fraction": phi, "temperature": 1.0 },
        "run": { "duration": 1.0 },
        "engine": { "mask": mask_choice(), "grid": grid_choice(), "remap": remap_choice(), "queue": queue_choice() }
    });
    Scenario::from_json(&json.to_string()).expect("gas scenario")
}

fn bed_scenario(n: usize) -> Scenario {
    let json = serde_json::json!({
        "name": format!("bench vibrated bed N={n}"),
        "seed": 6,
        "domain": { "width": n as f64 / 5.0, "x_boundary": "periodic", "y_boundary": "open" },
        "gravity": 1.0,
        "floor": { "gamma": 3.0, "frequency": 0.5, "restitution": 0.9 },
        "particles": { "count": n, "radius": RADIUS, "temperature": 0.5 },
        "collisions": { "restitution": 0.9 },
        "run": { "duration": 1.0 },
        "engine": { "mask": mask_choice(), "remap": remap_choice(), "queue": queue_choice() }
    });
    Scenario::from_json(&json.to_string()).expect("bed scenario")
}

/// Runs until `per_disk · N` collisions have happened since the start (not timed).
fn melt<F: Flight>(sim: &mut Simulation<F>, n: usize, per_disk: u64, max_time: f64) {
    let target = per_disk * n as u64;
    let chunk = (n as u64).max(10_000);
    let max_events = 20 * target.max(1);
    let start = sim.counts();
    loop {
        let c = sim.counts();
        if c.collisions() - start.collisions() >= target
            || c.popped() - start.popped() >= max_events
            || sim.time() >= max_time
        {
            break;
        }
        sim.step_events(chunk)
            .expect("step_events failed while melting");
    }
}

fn build_gas(n: usize, phi: f64, quick: bool) -> Engine {
    let t0 = Instant::now();
    let scenario = gas_scenario(n, phi);
    // The allocator settings of `vibrobed run` for this many disks (huge pages, blocks given back).
    vibrobed::platform::memory::for_disks(n);
    let (scene, disks) = Scene::build(&scenario).expect("Scene::build (gas)");
    let tb = Instant::now();
    let mut sim = Simulation::new(Straight, &scene, disks).expect("Simulation::new (gas)");
    let t1 = Instant::now();
    if !quick {
        melt(&mut sim, n, GAS_MELT_PER_DISK, f64::INFINITY);
    }
    eprintln!(
        "  [gas N={n} phi={phi}: Scene::build {:.1} s, Simulation::new {:.1} s, melt {:.1} s ({} collisions)]",
        (tb - t0).as_secs_f64(),
        (t1 - tb).as_secs_f64(),
        t1.elapsed().as_secs_f64(),
        sim.counts().collisions()
    );
    Engine::Gas(sim)
}

/// Warm-up of the bed (not timed): until 10 floor periods have passed, or 40 collisions per
/// disk, whichever comes first (the initial bed collapses, then fluidises).
const BED_MELT_PER_DISK: u64 = 40;
const BED_MELT_TIME: f64 = 20.0;

fn build_bed(n: usize, quick: bool) -> Engine {
    let t0 = Instant::now();
    let scenario = bed_scenario(n);
    vibrobed::platform::memory::for_disks(n);
    let (scene, disks) = Scene::build(&scenario).expect("Scene::build (bed)");
    let mut sim =
        Simulation::new(Ballistic { g: 1.0 }, &scene, disks).expect("Simulation::new (bed)");
    let t1 = Instant::now();
    if !quick {
        melt(&mut sim, n, BED_MELT_PER_DISK, BED_MELT_TIME);
    }
    let c = sim.counts();
    eprintln!(
        "  [bed N={n}: set-up {:.1} s, warm-up {:.1} s to t = {:.2} ({} collisions, {} floor)]",
        (t1 - t0).as_secs_f64(),
        t1.elapsed().as_secs_f64(),
        sim.time(),
        c.collisions(),
        c.floor
    );
    Engine::Bed(sim)
}

/// R timed repetitions of `k` events; medians of the rates.
fn measure(id: &str, engine: &mut Engine, n: usize, k: u64, reps: usize) -> Row {
    let mut coll_rates = Vec::with_capacity(reps);
    let mut event_rates = Vec::with_capacity(reps);
    let (c0, t_sim0) = with_sim!(engine, s => (s.counts(), s.time()));
    for _ in 0..reps {
        let before = with_sim!(engine, s => s.counts());
        let t = Instant::now();
        engine.step(k);
        let dt = t.elapsed().as_secs_f64();
        let after = with_sim!(engine, s => s.counts());
        coll_rates.push((after.collisions() - before.collisions()) as f64 / dt);
        event_rates.push(k as f64 / dt);
    }
    let (c1, t_sim1, bytes, mask) =
        with_sim!(engine, s => (s.counts(), s.time(), s.bytes(), s.mask().name));
    let dcoll = (c1.collisions() - c0.collisions()).max(1) as f64;
    Row {
        id: id.to_string(),
        n,
        k,
        coll_per_s: median(&mut coll_rates),
        events_per_s: median(&mut event_rates),
        bytes_per_disk: bytes as f64 / n as f64,
        mask,
        stale_ratio: (c1.stale - c0.stale) as f64 / dcoll,
        coll_per_remap: dcoll / (c1.rebuild - c0.rebuild).max(1) as f64,
        floor_frac: (c1.floor - c0.floor) as f64 / dcoll,
        sim_time: t_sim1 - t_sim0,
    }
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    let m = v.len() / 2;
    if v.len() % 2 == 1 {
        v[m]
    } else {
        0.5 * (v[m - 1] + v[m])
    }
}

/// Runs one criterion benchmark `group/name` on an engine built lazily (so a point the filter
/// leaves out costs nothing), then the table's own repetitions. Returns the row if it ran.
fn bench_point(
    c: &mut Criterion,
    group: &str,
    name: &str,
    kind: Kind,
    n: usize,
    opts: &Opts,
    build: impl FnOnce() -> Engine,
) -> Option<Row> {
    let k = if opts.quick {
        1_000
    } else {
        events_per_iter(kind, n)
    };
    let (_, rate) = plan(kind, n);
    let measure_secs = if opts.quick {
        0.1
    } else {
        (11.0 * k as f64 / rate).max(1.0)
    };
    let mut engine: Option<Engine> = None;
    let mut build = Some(build);
    {
        let mut g = c.benchmark_group(group);
        g.sampling_mode(SamplingMode::Flat)
            .sample_size(10)
            .warm_up_time(Duration::from_millis(500))
            .measurement_time(Duration::from_secs_f64(measure_secs))
            .throughput(Throughput::Elements(k));
        g.bench_function(name, |b| {
            let e = engine.get_or_insert_with(|| (build.take().expect("built once"))());
            b.iter_custom(|iters| {
                let t = Instant::now();
                for _ in 0..iters {
                    e.step(black_box(k));
                }
                t.elapsed()
            })
        });
        g.finish();
    }
    let mut e = engine?;
    if opts.quick {
        return None;
    }
    let row = measure(&format!("{group}/{name}"), &mut e, n, k, opts.reps);
    Some(row)
}

struct Opts {
    /// Criterion's `--test` mode (`cargo test --benches`): one tiny iteration, no table.
    quick: bool,
    reps: usize,
    bed: bool,
}

fn fmt_rate(r: f64) -> String {
    format!("{:.3} M", r / 1e6)
}

fn print_gas_table(rows: &[Row]) {
    println!();
    println!(
        "Elastic hard disks (radius 0.5), square periodic box; median of R repetitions of K events"
    );
    println!(
        "{:<20} {:>9} {:>8} {:>14} {:>12} {:>11} {:>5} {:>11} {:>11}",
        "point",
        "N",
        "K",
        "collisions/s",
        "events/s",
        "bytes/disk",
        "mask",
        "stale/coll",
        "coll/remap"
    );
    for r in rows {
        println!(
            "{:<20} {:>9} {:>8} {:>14} {:>12} {:>11.1} {:>5} {:>11.3} {:>11.0}",
            r.id,
            r.n,
            r.k,
            fmt_rate(r.coll_per_s),
            fmt_rate(r.events_per_s),
            r.bytes_per_disk,
            r.mask,
            r.stale_ratio,
            r.coll_per_remap
        );
    }
}

fn print_bed_table(rows: &[(Row, Row, Row)]) {
    println!();
    println!(
        "Vibrated bed (g 1, Γ 3, f 0.5, e 0.9, width N/5, periodic x, open top) vs elastic gas at the same N"
    );
    println!(
        "{:<16} {:>8} {:>13} {:>11} {:>5} {:>10} {:>7} {:>9} {:>13} {:>13} {:>9} {:>9}",
        "point",
        "N",
        "collisions/s",
        "bytes/disk",
        "mask",
        "stale/coll",
        "floor%",
        "sim time",
        "gas φ0.3",
        "gas φ0.7",
        "bed/0.3",
        "bed/0.7"
    );
    for (b, g3, g7) in rows {
        println!(
            "{:<16} {:>8} {:>13} {:>11.1} {:>5} {:>10.3} {:>6.1}% {:>9.2} {:>13} {:>13} {:>9.2} {:>9.2}",
            b.id,
            b.n,
            fmt_rate(b.coll_per_s),
            b.bytes_per_disk,
            b.mask,
            b.stale_ratio,
            100.0 * b.floor_frac,
            b.sim_time,
            fmt_rate(g3.coll_per_s),
            fmt_rate(g7.coll_per_s),
            b.coll_per_s / g3.coll_per_s,
            b.coll_per_s / g7.coll_per_s
        );
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let opts = Opts {
        quick: args.iter().any(|a| a == "--test"),
        reps: std::env::var("VIBROBED_BENCH_REPS")
            .ok()
            .and_then(|s| s.parse().ok())
            .filter(|&r: &usize| r > 0)
            .unwrap_or(5),
        bed: std::env::var("VIBROBED_BENCH_BED").map_or(true, |v| v != "0"),
    };
    let started = Instant::now();
    let mut c = Criterion::default().configure_from_args();

    let mut gas_rows = Vec::new();
    for &n in &GAS_N {
        for &phi in &GAS_PHI {
            let name = format!("{n}/phi{phi}");
            if let Some(row) = bench_point(&mut c, "gas", &name, Kind::Gas(phi), n, &opts, || {
                build_gas(n, phi, opts.quick)
            }) {
                gas_rows.push((phi, row));
            }
        }
    }

    let mut bed_rows = Vec::new();
    if opts.bed {
        for &n in &BED_N {
            let name = format!("{n}/gamma3");
            let Some(bed) = bench_point(&mut c, "bed", &name, Kind::Bed, n, &opts, || {
                build_bed(n, opts.quick)
            }) else {
                continue;
            };
            // The elastic gas at the same N, φ = 0.3 and 0.7: reuse the gas rows of this run,
            // else measure now (table only, no criterion).
            let gas_at = |phi: f64, rows: &[(f64, Row)]| -> Row {
                if let Some((_, r)) = rows.iter().find(|(p, r)| *p == phi && r.n == n) {
                    return r.clone();
                }
                let mut e = build_gas(n, phi, false);
                measure(
                    &format!("gas/{n}/phi{phi}"),
                    &mut e,
                    n,
                    events_per_iter(Kind::Gas(phi), n),
                    opts.reps,
                )
            };
            let g3 = gas_at(0.3, &gas_rows);
            let g7 = gas_at(0.7, &gas_rows);
            bed_rows.push((bed, g3, g7));
        }
    }

    c.final_summary();
    if !gas_rows.is_empty() {
        let rows: Vec<Row> = gas_rows.into_iter().map(|(_, r)| r).collect();
        print_gas_table(&rows);
    }
    if !bed_rows.is_empty() {
        print_bed_table(&bed_rows);
    }
    if !opts.quick && !(opts.bed) {
        println!("\n(vibrated bed skipped: VIBROBED_BENCH_BED=0)");
    }
    if !opts.quick {
        println!(
            "\nR = {} repetitions of K events per point; mask {}; whole benchmark {:.0} s",
            opts.reps,
            mask_choice(),
            started.elapsed().as_secs_f64()
        );
    }
}
