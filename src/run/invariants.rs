//! The invariants checked at each sample when a scene asks (`check_invariants`): no overlap,
//! the energy budget closed to round-off, and disks conserved where they enter and leave.

use super::views::StatesAt;
use crate::error::{Error, Result};
use crate::measure::{balance_error, Observables};
use crate::schemes::Integrator;

/// Invariant checks at a sample at time `t`: no overlap, energy balance.
pub(super) fn check_sample<E: Integrator>(
    sim: &E,
    t: f64,
    initial: &Observables,
    g: f64,
) -> Result<()> {
    sim.check_state(t)?;
    let now = Observables::of(&StatesAt(sim, t), sim.disks(), g);
    let flow = sim.energy_flow_at(t);
    let pool = sim.flow();
    let error = balance_error(
        initial,
        &now,
        &flow,
        pool.map_or(0.0, |f| f.energy_out - f.energy_in),
    );
    if error > 1e-9 {
        return Err(Error::Runtime(format!(
            "energy budget off by {error:e} (relative) at time {t}"
        )));
    }
    if let Some(f) = pool {
        // Number conservation: in − out = live − initial.
        let live = sim.disks().len() as u64;
        if f.initial + f.entered != live + f.left {
            return Err(Error::Runtime(format!(
                "disks not conserved at time {t}: {} at the start + {} in − {} out ≠ {live} live",
                f.initial, f.entered, f.left
            )));
        }
    }
    Ok(())
}
