//! The vector path of the engine's short hot loops, chosen at run time on the processor found:
//! four `f64` lanes (eight `u32` slots) at a time where it has AVX2, one at a time elsewhere;
//! on an Intel processor that also has AVX-512 (F and VL), the prediction's pair loop runs its
//! four lanes with the 32 vector registers and the mask registers AVX-512 adds (on AMD's Zen 5
//! that path measured slower than AVX2's, so AMD takes AVX2's unless asked). Every path does the
//! same operations in the same order, so the events are the same bit for bit whichever runs (the
//! tests run scenes on each and compare).
//!
//! `VIBROBED_CPU=scalar` in the environment asks for the one-at-a-time path on any processor
//! (`avx2` and `avx512` ask for theirs, an error where the processor lacks them; unset or
//! `auto`: the [preferred](Lanes::preferred) one).

use std::sync::OnceLock;

/// The environment variable that overrides the path found.
pub const OVERRIDE: &str = "VIBROBED_CPU";

/// How the engine's short hot loops run (the pair search, the shells' filter, the rows' slot
/// search, the calendar's sort of a short bucket). The four lanes are only ever chosen where the
/// processor has them: the value is made by this module alone, on what it finds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lanes(Width);

/// Whether the processor says it is Intel's.
fn made_by_intel() -> bool {
    vendor().is_some_and(|v| &v == b"GenuineIntel")
}

/// The processor's maker as CPUID names it (12 letters: "GenuineIntel", "AuthenticAMD").
fn vendor() -> Option<[u8; 12]> {
    #[cfg(target_arch = "x86_64")]
    {
        // CPUID leaf 0 exists on every x86-64 processor.
        #[allow(unused_unsafe)]
        let id = unsafe { std::arch::x86_64::__cpuid(0) };
        let bytes = [id.ebx, id.edx, id.ecx].map(u32::to_le_bytes).concat();
        bytes.try_into().ok()
    }
    #[cfg(not(target_arch = "x86_64"))]
    None
}

/// Declared narrowest first (`all_here` compares them in this order).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Width {
    /// One neighbour, one slot at a time: any processor.
    One,
    /// Four neighbours, eight slots at a time: x86-64 processors with AVX2.
    Avx2,
    /// As `Avx2`, the pair loop with AVX-512's registers: x86-64 processors with AVX-512F and
    /// AVX-512VL (Intel from Skylake-SP, AMD from Zen 4), taken unasked on Intel only.
    Avx512,
}

impl Lanes {
    /// One at a time, on any processor.
    pub const ONE_BY_ONE: Lanes = Lanes(Width::One);

    /// The path of this process: the [`OVERRIDE`]'s if it is set and valid, else the
    /// [preferred](Lanes::preferred) one. Found once (the command line reports an invalid
    /// setting before any run).
    pub fn found() -> Lanes {
        static FOUND: OnceLock<Lanes> = OnceLock::new();
        *FOUND.get_or_init(|| Lanes::from_environment().unwrap_or_else(|_| Lanes::preferred()))
    }

    /// The path taken where none is asked for: the widest, but AVX-512's only on Intel
    /// processors, where it was measured to win (Xeon, family 6 model 167: its 32 registers took
    /// 0.96–0.97 of AVX2's time, its mask registers 0.97–0.98 of that); on AMD's Zen 5 (family
    /// 26) it took 1.01–1.03 of AVX2's time (1.06–1.09 without the mask registers), and Zen 4
    /// was never measured on it.
    pub fn preferred() -> Lanes {
        let widest = Lanes::widest();
        if widest.avx512() && !made_by_intel() {
            return Lanes(Width::Avx2);
        }
        widest
    }

    /// The widest path this processor runs.
    pub fn widest() -> Lanes {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            let avx512 = std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("avx512vl");
            return Lanes(if avx512 { Width::Avx512 } else { Width::Avx2 });
        }
        Lanes::ONE_BY_ONE
    }

    /// The path the [`OVERRIDE`] asks for (unset: the preferred); what is wrong with its value if
    /// it is not one it takes or asks for a path this processor cannot run.
    pub fn from_environment() -> Result<Lanes, String> {
        match std::env::var(OVERRIDE) {
            Err(std::env::VarError::NotPresent) => Ok(Lanes::preferred()),
            Err(std::env::VarError::NotUnicode(_)) => Err("not text".into()),
            Ok(v) => match v.as_str() {
                "" | "auto" => Ok(Lanes::preferred()),
                "scalar" => Ok(Lanes::ONE_BY_ONE),
                "avx2" if Lanes::widest().avx2() => Ok(Lanes(Width::Avx2)),
                "avx2" => Err("this processor has no AVX2".into()),
                "avx512" if Lanes::widest().avx512() => Ok(Lanes::widest()),
                "avx512" => Err("this processor has no AVX-512 (F and VL)".into()),
                _ => Err(format!(
                    "unknown path {:?}: expected auto, scalar, avx2 or avx512",
                    v.chars().take(80).collect::<String>()
                )),
            },
        }
    }

    /// Whether the four AVX2 lanes run (then the processor has them).
    #[inline(always)]
    pub fn avx2(self) -> bool {
        self.0 != Width::One
    }

    /// Whether the pair loop's four lanes run with AVX-512's registers (then the processor has
    /// them).
    #[inline(always)]
    pub fn avx512(self) -> bool {
        self.0 == Width::Avx512
    }

    /// Every path this processor runs, the narrowest first: for the tests that compare them.
    pub fn all_here() -> Vec<Lanes> {
        let widest = Lanes::widest().0;
        [Width::One, Width::Avx2, Width::Avx512]
            .into_iter()
            .filter(|&w| w as u8 <= widest as u8)
            .map(Lanes)
            .collect()
    }

    /// The path's name, as [`OVERRIDE`] takes it.
    pub fn name(self) -> &'static str {
        match self.0 {
            Width::One => "scalar",
            Width::Avx2 => "avx2",
            Width::Avx512 => "avx512",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where none is asked for, the lanes are the widest the processor has, and AVX-512's
    /// registers only on Intel's processors.
    #[test]
    fn the_preferred_path_is_the_widest_but_avx512_only_on_intel() {
        let (preferred, widest) = (Lanes::preferred(), Lanes::widest());
        assert_eq!(preferred.avx2(), widest.avx2());
        assert_eq!(preferred.avx512(), widest.avx512() && made_by_intel());
        assert!(Lanes::all_here().contains(&preferred));
    }

    /// The maker's name is read whole, in CPUID's order of registers (EBX, EDX, ECX).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn the_vendor_is_read_whole() {
        let v = vendor().expect("x86-64 names its maker");
        assert!(v.iter().all(u8::is_ascii_alphanumeric), "{v:?}");
        let known = [&b"GenuineIntel"[..], b"AuthenticAMD"];
        let on_proc = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        for name in known {
            let text = std::str::from_utf8(name).expect("ASCII");
            if on_proc.contains(text) {
                assert_eq!(&v[..], name);
            }
        }
    }
}
