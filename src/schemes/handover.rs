//! The hybrid scheme: the exact engine while the bed is a gas, contact dynamics while it is dense,
//! and the run handed from one to the other as it turns.
//!
//! The exact engine's cost is its collisions; where disks endure in contact, inelastic collapse
//! and the rules that end it make those collisions unbounded in number. Contact dynamics costs a
//! fixed step whatever the contacts do. So the run watches the exact engine's collisions: when,
//! within a window (the floor's period), they pass [`EVENTS_PER_STEP`] per disk and step of
//! contact dynamics, the state at the last event is handed to contact dynamics. Contact dynamics
//! watches its enduring contacts: when, over a window, fewer than [`CONTACTS_OUT`] push per disk
//! and step, the bed has come apart and the state goes back to the exact engine. It also watches
//! what its contacts are: when more than [`IMPACTS_OUT`] of the contacts that push are impacts
//! (rebounds by Newton's law), the bed is a dense gas, not a network of enduring contacts, and
//! the state goes back too, with the exact engine's budget doubled so that such a bed stays
//! exact. The decisions are in the scene's own measure (steps of contact dynamics, not units of
//! time), and on counts, never on the wall clock: a run repeats bit for bit.
//!
//! Each part is a fresh engine built at the hand-over time on the scene at that instant (its
//! floor's phase moved on), from every disk's position, velocity and spin; a state from contact
//! dynamics first has its overlaps removed (the exact engine accepts none).

use super::contact::{Contact, ContactState};
use super::{Integrator, SavedState, SchemeStats, Setup};
use crate::engine::{EnergyFlow, EngineState, EventCounts, Progress, Scene, Simulation};
use crate::error::{Error, Result};
use crate::physics::disks::{Disks, Spins};
use crate::physics::flight::Flight;
use crate::scenario::Engine;
use serde::{Deserialize, Serialize};
use std::sync::atomic::AtomicBool;

/// Events of the exact engine per disk and step of contact dynamics above which it hands over:
/// about what a step of contact dynamics costs, counted in the exact engine's events (on the
/// shipped bed, 2 per disk and step of a fiftieth of the floor's period, 50 per unit time).
pub const EVENTS_PER_STEP: f64 = 2.0;

/// Steps of contact dynamics in a watch window without a vibrating floor (with one, the window
/// is its period).
const STEPS_PER_WINDOW: f64 = 50.0;

/// Contacts pushing per disk and step (averaged over a window) below which contact dynamics
/// hands back: a bed at rest has about two, a gas almost none.
pub const CONTACTS_OUT: f64 = 0.3;

/// The part of the contacts pushing in a window that are impacts (rebounds by Newton's law), above
/// which contact dynamics hands back: the bed is a dense gas, not a network of enduring contacts.
/// It lies between beds that ride or bounce on the floor and beds of many fluidized layers (the
/// accuracy page's hybrid section gives the parts measured).
pub const IMPACTS_OUT: f64 = 0.5;

/// Hand-backs of a dense gas double the exact engine's budget up to this many times (16×): a
/// bed that turns dense later in a long run goes to contact dynamics at a bounded cost.
const GAS_DOUBLINGS: u32 = 4;

/// The exact part's TC where the scene sets none. Inelastic collapse is a finite-time singularity
/// of the exact dynamics where a few disks start to ring, not a dense bed: TC removes it where it
/// starts. At 10⁻⁴ the fluidized shipped bed (Γ = 3) keeps its centre of mass and temperature
/// within the seed spread of the run without TC; at 10⁻³ both rose by 1–4 %.
pub const DEFAULT_TC: f64 = 1e-4;

/// The engine running now.
#[derive(Debug)]
enum Part<F: Flight> {
    Exact(Box<Simulation<F>>),
    Dense(Box<Contact<F>>),
}

/// What the parts before the present one did, for the totals.
#[derive(Debug, Default, Clone, Copy, Serialize, Deserialize)]
struct Done {
    counts: EventCounts,
    flow: EnergyFlow,
    virial: f64,
    max_overlap: f64,
    steps: DenseSteps,
    /// Simulated time spent in contact dynamics.
    dense_time: f64,
    handovers: u64,
}

/// Contact dynamics' steps and errors, summed over its parts.
#[derive(Debug, Default, Clone, Copy, Serialize, Deserialize)]
struct DenseSteps {
    /// Simulated time the steps took.
    time: f64,
    steps: u64,
    sweeps: u64,
    rebounds: u64,
    deep_overlaps: u64,
    max_boundary_penetration: f64,
}

impl DenseSteps {
    /// Adds a part's steps and errors.
    fn add(&mut self, part: SchemeStats) {
        self.time += part.step * part.steps as f64;
        self.steps += part.steps;
        self.sweeps += part.sweeps;
        self.rebounds += part.rebounds;
        self.deep_overlaps += part.deep_overlaps;
        self.max_boundary_penetration = self
            .max_boundary_penetration
            .max(part.max_boundary_penetration);
    }

    fn stats(&self) -> SchemeStats {
        SchemeStats {
            step: self.time / self.steps.max(1) as f64,
            steps: self.steps,
            sweeps: self.sweeps,
            rebounds: self.rebounds,
            deep_overlaps: self.deep_overlaps,
            max_boundary_penetration: self.max_boundary_penetration,
            ..SchemeStats::default()
        }
    }
}

/// The hybrid scheme's state, for a checkpoint: the present part's and the totals of the parts
/// before it, with the watch window.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct HandoverState {
    part: SavedPart,
    t0: f64,
    done: Done,
    window_end: f64,
    window_from: (u64, u64, u64),
    stay: u32,
    stayed: u32,
    gas_returns: u32,
}

/// The present part's state.
#[derive(Debug, Clone, Serialize, Deserialize)]
enum SavedPart {
    Exact(Box<EngineState>),
    Dense(Box<ContactState>),
}

/// `$body` with `$e` the engine running now (`&Box` or `&mut Box` of either), whichever it is.
macro_rules! on_part {
    ($part:expr, $e:ident => $body:expr) => {
        match $part {
            Part::Exact($e) => $body,
            Part::Dense($e) => $body,
        }
    };
}

/// The hybrid engine.
#[derive(Debug)]
pub struct Handover<F: Flight> {
    flight: F,
    scene: Scene,
    engine: Engine,
    /// The disks as the scenario numbers them (radii, masses, species); states are copied in.
    template: Disks,
    part: Part<F>,
    /// Absolute time of the present part's local time 0.
    t0: f64,
    done: Done,
    /// The watch window: its length, its end (absolute) and the present part's counts at its
    /// start (collisions for the exact engine; pushing contacts, steps and rebounds for contact
    /// dynamics).
    window: f64,
    window_end: f64,
    window_from: (u64, u64, u64),
    /// Windows contact dynamics keeps the run at least, doubled each time the exact engine
    /// hands back within one window.
    stay: u32,
    stayed: u32,
    /// Hand-backs of a dense gas ([`IMPACTS_OUT`]): each doubles the exact engine's budget, up to
    /// [`GAS_DOUBLINGS`].
    gas_returns: u32,
    exact_setup: Setup,
    /// `run.max_events`, over all parts (checked at each part's window ends too).
    event_limit: u64,
    /// The exact engine's collision budget in a window: [`EVENTS_PER_STEP`] per disk and step.
    budget: u64,
    /// [`CONTACTS_OUT`], unless a test sets another.
    contacts_out: f64,
    interrupt: Option<&'static AtomicBool>,
}

impl<F: Flight> Handover<F> {
    /// Starts with the exact engine on `disks`.
    pub fn new(flight: F, scene: &Scene, disks: Disks, engine: &Engine) -> Result<Handover<F>> {
        if !scene.inlets.is_empty() || scene.orifice.is_some() || scene.exit_height.is_some() {
            return Err(Error::input(
                "engine.scheme",
                "hybrid hands whole states between its engines: scenes whose disks enter or leave \
                 (inlets, an orifice, an exit height) need the event-driven scheme",
            ));
        }
        let event_limit = scene.max_events.unwrap_or(u64::MAX);
        let mut scene = scene.clone();
        scene.max_events = None;
        if scene.restitution.inelastic() && !scene.restitution.cured() {
            scene.restitution.tc = Some(DEFAULT_TC);
        }
        let template = disks.clone();
        let sim = Simulation::new(flight, &scene, disks)?;
        let mut exact_setup = Integrator::setup(&sim);
        exact_setup.scheme = "hybrid";
        // Contact dynamics must accept the scene too: refused knobs are found before the run.
        let step = Contact::new(flight, &scene, template.clone(), engine)?.step();
        let window = scene
            .floor
            .as_ref()
            .filter(|f| !f.is_static())
            .map_or(STEPS_PER_WINDOW * step, |f| f.period_or_one());
        let per_step = template.len().max(1) as f64 * window / step;
        Ok(Handover {
            flight,
            scene,
            engine: engine.clone(),
            template,
            part: Part::Exact(Box::new(sim)),
            t0: 0.0,
            done: Done::default(),
            window,
            window_end: window,
            window_from: (0, 0, 0),
            stay: 1,
            stayed: 0,
            gas_returns: 0,
            exact_setup,
            event_limit,
            budget: (EVENTS_PER_STEP * per_step) as u64,
            contacts_out: CONTACTS_OUT,
            interrupt: None,
        })
    }

    /// The same with other thresholds of the hand-overs (tests): `events_per_step` in place of
    /// [`EVENTS_PER_STEP`], `contacts_out` of [`CONTACTS_OUT`].
    pub fn with_thresholds(mut self, events_per_step: f64, contacts_out: f64) -> Handover<F> {
        self.budget = (self.budget as f64 * events_per_step / EVENTS_PER_STEP) as u64;
        self.contacts_out = contacts_out;
        self
    }

    /// The scene at absolute time `t`: its floor's phase moved on to `t`.
    fn scene_at(&self, t: f64) -> Scene {
        let mut scene = self.scene.clone();
        if let Some(f) = &mut scene.floor {
            f.rebase(t);
        }
        scene
    }

    /// Every disk's state at the present part's local time `tau`, in the scenario's numbering.
    fn disks_at(&self, tau: f64) -> Disks {
        let mut disks = self.template.clone();
        let mut fill = |i: usize, s: [f64; 4]| {
            let m = &mut disks.motion[i];
            (m.x, m.y, m.vx, m.vy, m.t) = (s[0], s[1], s[2], s[3], 0.0);
        };
        let spins = match &self.part {
            Part::Exact(sim) => {
                Integrator::visit_states(&**sim, tau, &mut fill);
                Integrator::spins_at(&**sim, tau)
            }
            Part::Dense(c) => {
                c.visit_states(tau, &mut fill);
                c.spins_at(tau)
            }
        };
        if let (Some(s), Some(spins)) = (&mut disks.spins, spins) {
            let (phase, omega): (Vec<f64>, Vec<f64>) = spins.into_iter().unzip();
            *s = Spins {
                q: s.q,
                omega,
                phase,
            };
        }
        disks
    }

    /// Banks the present part's totals before it is replaced.
    fn bank(&mut self) {
        let tau = self.local_time();
        let (counts, flow) = (self.part_counts(), self.part_flow(tau));
        let (virial, overlap) = (self.part_virial(), self.part_max_overlap());
        let d = &mut self.done;
        d.counts += counts;
        d.flow.injected += flow.injected;
        d.flow.dissipated += flow.dissipated;
        d.flow.floor_impulse += flow.floor_impulse;
        d.virial += virial;
        d.max_overlap = d.max_overlap.max(overlap);
        d.handovers += 1;
        if let Part::Dense(c) = &self.part {
            d.steps.add(c.approximation().unwrap_or_default());
            d.dense_time += tau;
        }
    }

    /// Hands the run to the other engine at the present part's time.
    fn hand_over(&mut self) -> Result<()> {
        let tau = self.local_time();
        let t = self.t0 + tau;
        let scene = self.scene_at(t);
        let next = match &mut self.part {
            Part::Exact(_) => {
                let disks = self.disks_at(tau);
                Part::Dense(Box::new(Contact::new(
                    self.flight,
                    &scene,
                    disks,
                    &self.engine,
                )?))
            }
            Part::Dense(c) => {
                // The separation's lifts are made for the exact engine: in a tall bed they add
                // up to a push of the whole bed. A refused hand-back undoes them.
                let before = c.state();
                c.separate();
                let disks = self.disks_at(tau);
                match Simulation::new(self.flight, &scene, disks) {
                    Ok(sim) => Part::Exact(Box::new(sim)),
                    // Not separable now (a deep overlap): contact dynamics carries on as it was.
                    Err(_) => {
                        if let Part::Dense(c) = &mut self.part {
                            c.restore(before)?;
                        }
                        return Ok(());
                    }
                }
            }
        };
        self.bank();
        self.part = next;
        self.t0 = t;
        self.attach_part();
        self.window_end = t + self.window;
        self.window_from = (0, 0, 0);
        self.stayed = 0;
        Ok(())
    }

    /// Gives a new present part the run's interrupt, and the run's clock and collisions at its
    /// start for what it publishes.
    fn attach_part(&mut self) {
        if let Some(flag) = self.interrupt {
            self.part_set_interrupt(flag);
        }
        let collisions = self.done.counts.collisions();
        if let Part::Exact(sim) = &mut self.part {
            sim.set_published_origin(self.t0, collisions);
        }
    }

    fn local_time(&self) -> f64 {
        on_part!(&self.part, e => Integrator::time(e.as_ref()))
    }

    fn part_counts(&self) -> EventCounts {
        on_part!(&self.part, e => Integrator::counts(e.as_ref()))
    }

    fn part_flow(&self, tau: f64) -> EnergyFlow {
        on_part!(&self.part, e => Integrator::energy_flow_at(e.as_ref(), tau))
    }

    fn part_virial(&self) -> f64 {
        on_part!(&self.part, e => Integrator::virial(e.as_ref()))
    }

    fn part_max_overlap(&self) -> f64 {
        on_part!(&self.part, e => Integrator::max_overlap(e.as_ref()))
    }

    fn part_set_interrupt(&mut self, flag: &'static AtomicBool) {
        on_part!(&mut self.part, e => Integrator::set_interrupt(e.as_mut(), flag))
    }

    /// The exact engine runs to `target` within the window's collision budget; past it, the run
    /// goes to contact dynamics.
    fn exact_to(&mut self, target: f64) -> Result<Option<Progress>> {
        let budget = self
            .budget
            .saturating_mul(1 << self.gas_returns.min(GAS_DOUBLINGS));
        let stop = target.min(self.window_end);
        let Part::Exact(sim) = &mut self.part else {
            unreachable!()
        };
        let from = self.window_from.0;
        let before = self.done.counts.guarded();
        let left = self.event_limit.saturating_sub(before);
        sim.set_event_limit((from + budget).min(left));
        match sim.advance_to(stop - self.t0)? {
            Progress::Reached => {
                if stop >= self.window_end {
                    let spent = Integrator::counts(&**sim).guarded() - from;
                    self.window_from.0 += spent;
                    self.window_end += self.window;
                    self.stayed = self.stayed.saturating_add(1);
                }
                // Reached is trusted, not re-derived from the times: `t0 + (target - t0)` can
                // fall an ulp short of `target`, and a loop on the times would never end.
                Ok((stop >= target).then_some(Progress::Reached))
            }
            Progress::EventLimit
                if before + Integrator::counts(&**sim).guarded() >= self.event_limit =>
            {
                Ok(Some(Progress::EventLimit))
            }
            Progress::EventLimit => {
                if self.stayed == 0 {
                    self.stay = (2 * self.stay).min(64);
                } else {
                    self.stay = 1;
                }
                self.hand_over()?;
                Ok(None)
            }
            other => Ok(Some(other)),
        }
    }

    /// Contact dynamics runs to `target`; at each window's end it hands back if the bed has come
    /// apart.
    fn dense_to(&mut self, target: f64) -> Result<Option<Progress>> {
        let stop = target.min(self.window_end);
        let Part::Dense(c) = &mut self.part else {
            unreachable!()
        };
        match c.advance_to(stop - self.t0)? {
            Progress::Reached => {}
            other => return Ok(Some(other)),
        }
        if stop < self.window_end {
            return Ok(None);
        }
        let counts = c.counts();
        let pushing = counts.pair + counts.floor + counts.wall + counts.lid;
        let stats = c.approximation().unwrap_or_default();
        let (p0, s0, r0) = self.window_from;
        let disk_steps = self.template.len().max(1) as f64 * (stats.steps - s0).max(1) as f64;
        let pushing_per = (pushing - p0) as f64 / disk_steps;
        self.window_from = (pushing, stats.steps, stats.rebounds);
        self.window_end += self.window;
        self.stayed = self.stayed.saturating_add(1);
        let impacts = (stats.rebounds - r0) as f64 / (pushing - p0).max(1) as f64;
        if impacts > IMPACTS_OUT {
            self.hand_over()?;
            if matches!(self.part, Part::Exact(_)) {
                self.gas_returns += 1;
            }
        } else if self.stayed >= self.stay && pushing_per < self.contacts_out {
            self.hand_over()?;
        }
        Ok(None)
    }
}

impl<F: Flight> Integrator for Handover<F> {
    fn set_interrupt(&mut self, flag: &'static AtomicBool) {
        self.interrupt = Some(flag);
        self.part_set_interrupt(flag);
    }
    fn disks(&self) -> &Disks {
        on_part!(&self.part, e => Integrator::disks(e.as_ref()))
    }
    fn time(&self) -> f64 {
        self.t0 + self.local_time()
    }
    fn advance_to(&mut self, target: f64) -> Result<Progress> {
        loop {
            if self.counts().guarded() >= self.event_limit {
                return Ok(Progress::EventLimit);
            }
            let left = match self.part {
                Part::Exact(_) if self.time() < target => self.exact_to(target)?,
                Part::Dense(ref c) if c.can_step_to(target - self.t0) => self.dense_to(target)?,
                _ => return Ok(Progress::Reached),
            };
            if let Some(progress) = left {
                return Ok(progress);
            }
        }
    }
    fn visit_states(&self, t: f64, visit: impl FnMut(usize, [f64; 4])) {
        on_part!(&self.part, e => Integrator::visit_states(e.as_ref(), t - self.t0, visit))
    }
    fn floor_height_at(&self, t: f64) -> Option<f64> {
        on_part!(&self.part, e => Integrator::floor_height_at(e.as_ref(), t - self.t0))
    }
    fn rotational_energy(&self, t: f64) -> Option<f64> {
        on_part!(&self.part, e => Integrator::rotational_energy(e.as_ref(), t - self.t0))
    }
    fn spins_at(&self, t: f64) -> Option<Vec<(f64, f64)>> {
        on_part!(&self.part, e => Integrator::spins_at(e.as_ref(), t - self.t0))
    }
    fn inertia_factor(&self) -> Option<f64> {
        self.template.spins.as_ref().map(|s| s.q)
    }
    fn counts(&self) -> EventCounts {
        let mut c = self.done.counts;
        c += self.part_counts();
        c
    }
    fn energy_flow_at(&self, t: f64) -> EnergyFlow {
        let (d, p) = (self.done.flow, self.part_flow(t - self.t0));
        EnergyFlow {
            injected: d.injected + p.injected,
            dissipated: d.dissipated + p.dissipated,
            floor_impulse: d.floor_impulse + p.floor_impulse,
        }
    }
    fn virial(&self) -> f64 {
        self.done.virial + self.part_virial()
    }
    fn max_overlap(&self) -> f64 {
        self.done.max_overlap.max(self.part_max_overlap())
    }
    fn check_state(&self, t: f64) -> Result<()> {
        match &self.part {
            Part::Exact(sim) => Integrator::check_state(&**sim, t - self.t0),
            Part::Dense(_) => Ok(()),
        }
    }
    fn stall_report(&self) -> Option<&str> {
        match &self.part {
            Part::Exact(sim) => Integrator::stall_report(&**sim),
            Part::Dense(_) => None,
        }
    }
    fn setup(&self) -> Setup {
        self.exact_setup.clone()
    }
    fn approximation(&self) -> Option<SchemeStats> {
        let mut steps = self.done.steps;
        let mut dense_time = self.done.dense_time;
        if let Part::Dense(c) = &self.part {
            steps.add(c.approximation().unwrap_or_default());
            dense_time += c.time();
        }
        let s = SchemeStats {
            handovers: self.done.handovers,
            dense_time,
            ..steps.stats()
        };
        (s.steps > 0).then_some(s)
    }
    fn disks_at_rest(&self) -> usize {
        on_part!(&self.part, e => Integrator::disks_at_rest(e.as_ref()))
    }
    fn at_rest_since(&self) -> Option<f64> {
        on_part!(&self.part, e => Integrator::at_rest_since(e.as_ref())).map(|t| t + self.t0)
    }
    fn rest_wakes(&self) -> u64 {
        match &self.part {
            Part::Exact(sim) => Integrator::rest_wakes(&**sim),
            Part::Dense(_) => 0,
        }
    }
    fn saved_state(&self) -> Option<SavedState> {
        let part = match &self.part {
            Part::Exact(sim) => SavedPart::Exact(Box::new(sim.state())),
            Part::Dense(c) => SavedPart::Dense(Box::new(c.state())),
        };
        Some(SavedState::Hybrid(Box::new(HandoverState {
            part,
            t0: self.t0,
            done: self.done,
            window_end: self.window_end,
            window_from: self.window_from,
            stay: self.stay,
            stayed: self.stayed,
            gas_returns: self.gas_returns,
        })))
    }
    fn restore_state(&mut self, state: SavedState) -> Result<()> {
        let SavedState::Hybrid(state) = state else {
            return Err(SavedState::other_scheme("event-driven"));
        };
        let state = *state;
        self.part = match state.part {
            SavedPart::Exact(saved) => {
                let mut sim = Simulation::new(self.flight, &self.scene, self.template.clone())?;
                sim.restore(*saved)?;
                Part::Exact(Box::new(sim))
            }
            SavedPart::Dense(saved) => {
                let scene = self.scene_at(state.t0);
                let mut c = Contact::new(self.flight, &scene, self.template.clone(), &self.engine)?;
                c.restore(*saved)?;
                Part::Dense(Box::new(c))
            }
        };
        self.t0 = state.t0;
        self.done = state.done;
        self.window_end = state.window_end;
        self.window_from = state.window_from;
        self.stay = state.stay;
        self.stayed = state.stayed;
        self.gas_returns = state.gas_returns;
        self.attach_part();
        Ok(())
    }
}
