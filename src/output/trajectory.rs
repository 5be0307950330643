//! Trajectories in extended XYZ (`.xyz`), the text format that OVITO, ASE, ParaView (through
//! ASE or OVITO) and plain scripts read.
//!
//! # Format
//!
//! One block per frame, each complete (count line, comment line, one line per disk):
//!
//! ```text
//! 3
//! Lattice="10.0 0 0 0 8.0 0 0 0 1" Properties=species:S:1:pos:R:3:radius:R:1:velo:R:3 Time=0.5 floor_height=0.01 frame=1 pbc="F F F"
//! H 1.25 0.5 0 0.5 0.3 -0.2 0
//! H 2.5 1.75 0 0.5 -1.0 0.1 0
//! He 4.0 2.5 0 0.25 0.0 0.0 0
//! ```
//!
//! - `pos` and `velo` have three components with z = 0: ASE's `Atoms` holds 3D vectors, and
//!   OVITO reads a 2D file the same way.
//! - `species`: ASE accepts only chemical symbols, so species k (the radius class, as in the
//!   recording's class ids) is written as the element of atomic number k + 1 (`H`, `He`, `Li`, …);
//!   the disk's real size is in the `radius` column (OVITO maps `radius` to its particle radius).
//! - `Lattice`: the cell vectors (width, 0, 0), (0, height, 0), (0, 0, 1), with the height of the
//!   lid or of the periodic cell, or, for an open top, the highest disk top of the frame (at least
//!   1): an open bed has no cell height of its own. `pbc` says which directions are periodic.
//! - `Time` is the simulated time, `floor_height` the floor's height at that time (absent without
//!   a floor), `frame` the frame number.
//! - Rough disks add two columns, `angle:R:1:omega:R:1` ([`ROUGH_PROPERTIES`]): each disk's
//!   orientation in [0, 2π) and its angular velocity.
//! - Scenes whose disks leave or enter (a floor orifice, an exit height, inlets) add a last column, `id:I:1`: each live disk's
//!   id (its scenario number), the frame listing only the live disks in the order of their ids.
//! - Numbers are written in the shortest form that reads back to the same `f64`, always as reals
//!   (`2.0`, not `2`, so that readers type `Time` alike in every frame).
//!
//! # Atomic write
//!
//! Frames go to `FILE.partial` beside `FILE`; [`TrajectoryWriter::finish`] (or dropping the
//! writer, e.g. after an error elsewhere or an interrupt) flushes the complete frames and renames
//! the file into place. A process killed outright leaves only `FILE.partial`, never a truncated
//! `FILE`. A frame that cannot be written (a full disk, a quota, an I/O error) fails the writer:
//! the error names the file and the operating system's reason, and `FILE.partial` is removed.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use super::frame::{FrameSink, FrameView, SceneLayout};
use super::partial::Partial;
use crate::error::Error;

/// The element symbols written for species 0, 1, 2, … (atomic numbers 1, 2, 3, …).
const SYMBOLS: [&str; 36] = [
    "H", "He", "Li", "Be", "B", "C", "N", "O", "F", "Ne", "Na", "Mg", "Al", "Si", "P", "S", "Cl",
    "Ar", "K", "Ca", "Sc", "Ti", "V", "Cr", "Mn", "Fe", "Co", "Ni", "Cu", "Zn", "Ga", "Ge", "As",
    "Se", "Br", "Kr",
];

/// The column layout written on every comment line.
pub const PROPERTIES: &str = "species:S:1:pos:R:3:radius:R:1:velo:R:3";

/// The column layout of rough disks: the orientation and angular velocity follow.
pub const ROUGH_PROPERTIES: &str = "species:S:1:pos:R:3:radius:R:1:velo:R:3:angle:R:1:omega:R:1";

/// The chemical symbol standing for species `k` (see the [module documentation](self)); species
/// beyond the table (36 and up) reuse its last symbol.
pub fn species_symbol(k: u32) -> &'static str {
    SYMBOLS[(k as usize).min(SYMBOLS.len() - 1)]
}

/// Writes `v` in the shortest form that reads back to the same value, always with a decimal
/// point or an exponent so that readers see a real (`2.0`, `0.1`, `1.5e-7`, `1e16`; `NaN`, `inf`).
fn push_real(out: &mut String, v: f64) {
    let _ = write!(out, "{v:?}");
}

/// Streams frames to an extended XYZ file (see the [module documentation](self)).
#[derive(Debug)]
pub struct TrajectoryWriter {
    out: Option<BufWriter<File>>,
    partial: Partial,
    layout: SceneLayout,
    frames: u64,
    /// One frame's text, reused.
    text: String,
}

impl TrajectoryWriter {
    /// Opens `FILE.partial` beside `path` for writing (truncating it). `layout` gives the cell.
    pub fn create(path: &Path, layout: &SceneLayout) -> Result<Self, String> {
        let (partial, file) = Partial::create(path).map_err(|e| {
            format!(
                "cannot create trajectory {}: {e}",
                super::partial::partial_name(path).display()
            )
        })?;
        Ok(Self {
            out: Some(BufWriter::with_capacity(1 << 20, file)),
            partial,
            layout: layout.clone(),
            frames: 0,
            text: String::new(),
        })
    }

    /// Frames written so far.
    pub fn frames(&self) -> u64 {
        self.frames
    }

    /// Appends one frame (all disks at `f.time`, with rough disks' `f.spins`); `f.series` is not
    /// written. Fails when the per-disk slices differ in length or the file cannot be written.
    pub fn frame(&mut self, f: &FrameView) -> Result<(), String> {
        let (n, spins) = (f.x.len(), f.spins);
        if [f.y.len(), f.vx.len(), f.vy.len(), f.radius.len()]
            .iter()
            .any(|&m| m != n)
            || spins.is_some_and(|s| s.len() != n)
            || (!f.species.is_empty() && f.species.len() != n)
        {
            return Err(format!(
                "trajectory frame {}: per-disk slices differ in length",
                f.index
            ));
        }
        let height = match (self.layout.top, self.layout.y_periodic) {
            (Some(top), _) => top,
            (None, _) => {
                f.y.iter()
                    .zip(f.radius)
                    .map(|(y, r)| y + r)
                    .fold(1.0, f64::max)
            }
        };
        let t = &mut self.text;
        t.clear();
        let _ = writeln!(t, "{n}");
        t.push_str("Lattice=\"");
        push_real(t, self.layout.width);
        t.push_str(" 0 0 0 ");
        push_real(t, height);
        let properties = if spins.is_some() {
            ROUGH_PROPERTIES
        } else {
            PROPERTIES
        };
        let id = if f.ids.is_empty() { "" } else { ":id:I:1" };
        let _ = write!(t, " 0 0 0 1\" Properties={properties}{id} Time=");
        push_real(t, f.time);
        if let Some(h) = f.floor_height {
            t.push_str(" floor_height=");
            push_real(t, h);
        }
        let flag = |b: bool| if b { 'T' } else { 'F' };
        let _ = writeln!(
            t,
            " frame={} pbc=\"{} {} F\"",
            f.index,
            flag(self.layout.x_periodic),
            flag(self.layout.y_periodic)
        );
        for i in 0..n {
            t.push_str(species_symbol(f.species.get(i).copied().unwrap_or(0)));
            for v in [f.x[i], f.y[i]] {
                t.push(' ');
                push_real(t, v);
            }
            t.push_str(" 0 ");
            push_real(t, f.radius[i]);
            for v in [f.vx[i], f.vy[i]] {
                t.push(' ');
                push_real(t, v);
            }
            t.push_str(" 0");
            if let Some(&(angle, omega)) = spins.and_then(|s| s.get(i)) {
                for v in [angle, omega] {
                    t.push(' ');
                    push_real(t, v);
                }
            }
            if let Some(id) = f.ids.get(i) {
                let _ = write!(t, " {id}");
            }
            t.push('\n');
        }
        let out = self.out.as_mut().ok_or("trajectory already closed")?;
        if let Err(e) = out.write_all(self.text.as_bytes()) {
            self.discard();
            return Err(format!(
                "cannot write trajectory {}: {e}",
                self.partial.tmp.display()
            ));
        }
        self.frames += 1;
        Ok(())
    }

    /// Flushes the frames and renames `FILE.partial` to `FILE`; returns the number of frames.
    pub fn finish(mut self) -> Result<u64, String> {
        self.close()?;
        Ok(self.frames)
    }

    /// The temporary file this writer writes (`FILE.partial`).
    pub fn partial(&self) -> &Partial {
        &self.partial
    }

    fn close(&mut self) -> Result<(), String> {
        let Some(out) = self.out.take() else {
            return Ok(());
        };
        let done = out
            .into_inner()
            .map_err(|e| e.into_error())
            .and_then(|file| self.partial.commit(file));
        done.map_err(|e| {
            self.partial.discard();
            format!(
                "cannot write trajectory {}: {e}",
                self.partial.tmp.display()
            )
        })
    }

    /// Stops writing and removes the temporary file.
    fn discard(&mut self) {
        // The buffered rest is dropped unwritten: the file is going.
        if let Some(out) = self.out.take() {
            let _ = out.into_parts();
        }
        self.partial.discard();
    }
}

/// A run streams its trajectory frames as it streams its recording; a trajectory has no text.
impl FrameSink for TrajectoryWriter {
    fn frame(&mut self, frame: &FrameView) -> crate::error::Result<()> {
        TrajectoryWriter::frame(self, frame).map_err(Error::Io)
    }
    fn log_text(&mut self, _time: f64, _level: &str, _text: &str) -> crate::error::Result<()> {
        Ok(())
    }
    fn finish(self: Box<Self>) -> crate::error::Result<()> {
        TrajectoryWriter::finish(*self).map(drop).map_err(Error::Io)
    }
    fn file(&self) -> Option<Partial> {
        Some(self.partial().clone())
    }
}

impl Drop for TrajectoryWriter {
    /// A writer dropped without [`finish`](TrajectoryWriter::finish) (an error in the run) still
    /// puts its complete frames in place.
    fn drop(&mut self) {
        let _ = self.close();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_read_back_exactly() {
        for v in [
            0.0, 1.0, -2.5, 0.1, 1e-4, 9.99e-5, 1.5e-7, -3.0e-300, 123456.789, 1e15, 2e20, 0.3,
        ] {
            let mut s = String::new();
            push_real(&mut s, v);
            assert_eq!(s.parse::<f64>().unwrap(), v, "{s}");
            assert!(s.len() <= 24, "{s}");
        }
        for (v, text) in [
            (1.5e-7, "1.5e-7"),
            (2.0, "2.0"),
            (0.0, "0.0"),
            (1e16, "1e16"),
        ] {
            let mut s = String::new();
            push_real(&mut s, v);
            assert_eq!(s, text);
        }
    }

    #[test]
    fn species_are_element_symbols() {
        assert_eq!(species_symbol(0), "H");
        assert_eq!(species_symbol(1), "He");
        assert_eq!(species_symbol(5), "C");
        assert_eq!(species_symbol(1000), "Kr");
    }
}
