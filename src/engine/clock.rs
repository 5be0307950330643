//! The engine's clock: a local time that restarts at every mapping, an epoch summed with
//! compensation, and phases and periodic coordinates kept reduced.

/// The absolute time of the engine's local clock zero, summed with compensation (Neumaier) so
/// that millions of re-basings add no drift: absolute = `hi + (lo + local)`.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub(super) struct Epoch {
    pub(super) hi: f64,
    pub(super) lo: f64,
}

impl Epoch {
    /// Moves the epoch forward by `dt`.
    pub(super) fn advance(&mut self, dt: f64) {
        let sum = self.hi + dt;
        let err = if self.hi.abs() >= dt.abs() {
            (self.hi - sum) + dt
        } else {
            (dt - sum) + self.hi
        };
        self.hi = sum;
        self.lo += err;
    }

    /// Absolute time of local time `local`.
    #[inline]
    pub(super) fn absolute(&self, local: f64) -> f64 {
        self.hi + (self.lo + local)
    }

    /// Local time of absolute time `t`.
    #[inline]
    pub(super) fn local(&self, t: f64) -> f64 {
        (t - self.hi) - self.lo
    }
}
