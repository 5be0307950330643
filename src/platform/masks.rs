//! Lane masks of the four-lane loops, kept as each vector path keeps them: AVX2's comparisons
//! give a vector of all-ones or all-zeros lanes that a blend reads; AVX-512's give a mask
//! register that selects directly. The same lanes are selected either way (the arithmetic is
//! the caller's, untouched): the choice only changes how many instructions a selection costs
//! and how long it waits on its comparison.

use std::arch::x86_64::*;

/// Comparisons and selections of four `f64` (or `i64`) lanes.
///
/// # Safety
///
/// Every method runs only inside a function compiled for the path's instructions (AVX2;
/// AVX-512F and VL for [`Registers`]), into which it is inlined.
pub(crate) trait Masks: Copy {
    /// One flag per lane.
    type Mask: Copy;
    /// `a OP b` lane by lane (`OP` one of the `_CMP_*` predicates).
    unsafe fn cmp<const OP: i32>(a: __m256d, b: __m256d) -> Self::Mask;
    /// `a > b` lane by lane, as signed 64-bit integers.
    unsafe fn gt_i64(a: __m256i, b: __m256i) -> Self::Mask;
    /// Both.
    unsafe fn and(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Either.
    unsafe fn or(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// `b` and not `a`.
    unsafe fn and_not(a: Self::Mask, b: Self::Mask) -> Self::Mask;
    /// Per lane, `yes` where `m` is set, else `no`.
    unsafe fn select(m: Self::Mask, yes: __m256d, no: __m256d) -> __m256d;
    /// As [`select`](Masks::select), on integer lanes.
    unsafe fn select_i64(m: Self::Mask, yes: __m256i, no: __m256i) -> __m256i;
}

/// AVX2's masks: vectors of all-ones or all-zeros lanes.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Vectors;

impl Masks for Vectors {
    type Mask = __m256d;
    #[inline(always)]
    unsafe fn cmp<const OP: i32>(a: __m256d, b: __m256d) -> __m256d {
        _mm256_cmp_pd::<OP>(a, b)
    }
    #[inline(always)]
    unsafe fn gt_i64(a: __m256i, b: __m256i) -> __m256d {
        _mm256_castsi256_pd(_mm256_cmpgt_epi64(a, b))
    }
    #[inline(always)]
    unsafe fn and(a: __m256d, b: __m256d) -> __m256d {
        _mm256_and_pd(a, b)
    }
    #[inline(always)]
    unsafe fn or(a: __m256d, b: __m256d) -> __m256d {
        _mm256_or_pd(a, b)
    }
    #[inline(always)]
    unsafe fn and_not(a: __m256d, b: __m256d) -> __m256d {
        _mm256_andnot_pd(a, b)
    }
    #[inline(always)]
    unsafe fn select(m: __m256d, yes: __m256d, no: __m256d) -> __m256d {
        _mm256_blendv_pd(no, yes, m)
    }
    #[inline(always)]
    unsafe fn select_i64(m: __m256d, yes: __m256i, no: __m256i) -> __m256i {
        _mm256_castpd_si256(_mm256_blendv_pd(
            _mm256_castsi256_pd(no),
            _mm256_castsi256_pd(yes),
            m,
        ))
    }
}

/// AVX-512's masks: mask registers, set by the comparisons and read by the selections (no
/// vector of flags in between). Unused in a baseline build (its AVX-512 path calls the AVX2
/// loop as it is).
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(target_feature = "avx2"), allow(dead_code))]
pub(crate) struct Registers;

impl Masks for Registers {
    type Mask = __mmask8;
    #[inline(always)]
    unsafe fn cmp<const OP: i32>(a: __m256d, b: __m256d) -> __mmask8 {
        _mm256_cmp_pd_mask::<OP>(a, b)
    }
    #[inline(always)]
    unsafe fn gt_i64(a: __m256i, b: __m256i) -> __mmask8 {
        _mm256_cmpgt_epi64_mask(a, b)
    }
    #[inline(always)]
    unsafe fn and(a: __mmask8, b: __mmask8) -> __mmask8 {
        a & b
    }
    #[inline(always)]
    unsafe fn or(a: __mmask8, b: __mmask8) -> __mmask8 {
        a | b
    }
    #[inline(always)]
    unsafe fn and_not(a: __mmask8, b: __mmask8) -> __mmask8 {
        !a & b
    }
    #[inline(always)]
    unsafe fn select(m: __mmask8, yes: __m256d, no: __m256d) -> __m256d {
        _mm256_mask_blend_pd(m, no, yes)
    }
    #[inline(always)]
    unsafe fn select_i64(m: __mmask8, yes: __m256i, no: __m256i) -> __m256i {
        _mm256_mask_blend_epi64(m, no, yes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// Every comparison, combination and selection of the two kinds of masks on the same
    /// lanes: the bits of what each selects, as `[u64; 4]`.
    unsafe fn outcomes<K: Masks>(a: __m256d, b: __m256d, x: __m256d, y: __m256d) -> Vec<[u64; 4]> {
        let bits = |v: __m256d| std::mem::transmute::<__m256d, [u64; 4]>(v);
        let bits_i = |v: __m256i| std::mem::transmute::<__m256i, [u64; 4]>(v);
        let (lt, le) = (K::cmp::<_CMP_LT_OQ>(a, b), K::cmp::<_CMP_LE_OQ>(a, b));
        let (gt, ge) = (K::cmp::<_CMP_GT_OQ>(a, b), K::cmp::<_CMP_GE_OQ>(a, b));
        let eq = K::cmp::<_CMP_EQ_OQ>(a, b);
        let (xi, yi) = (_mm256_castpd_si256(x), _mm256_castpd_si256(y));
        let above = K::gt_i64(xi, yi);
        let mut out = vec![];
        for m in [
            lt,
            le,
            gt,
            ge,
            eq,
            above,
            K::and(lt, ge),
            K::or(gt, eq),
            K::and_not(le, ge),
        ] {
            out.push(bits(K::select(m, x, y)));
            out.push(bits_i(K::select_i64(m, xi, yi)));
        }
        out
    }

    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    unsafe fn registers(a: __m256d, b: __m256d, x: __m256d, y: __m256d) -> Vec<[u64; 4]> {
        outcomes::<Registers>(a, b, x, y)
    }

    #[target_feature(enable = "avx2")]
    unsafe fn vectors(a: __m256d, b: __m256d, x: __m256d, y: __m256d) -> Vec<[u64; 4]> {
        outcomes::<Vectors>(a, b, x, y)
    }

    #[test]
    fn mask_registers_select_the_lanes_vectors_of_flags_select() {
        if !crate::platform::cpu::Lanes::widest().avx512() {
            eprintln!("no AVX-512 here: nothing to compare");
            return;
        }
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        // Small integers (equal values often), signed zeros, infinities and NaN among them.
        let special = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let value = |rng: &mut rand_xoshiro::Xoshiro256PlusPlus| {
            if rng.random_bool(0.3) {
                special[rng.random_range(0..special.len())]
            } else {
                rng.random_range(-3..=3) as f64
            }
        };
        for _ in 0..2000 {
            let mut lanes = [[0.0; 4]; 4];
            for v in lanes.iter_mut().flatten() {
                *v = value(&mut rng);
            }
            // SAFETY: the processor has AVX2, AVX-512F and VL (checked above).
            unsafe {
                let [a, b, x, y] = lanes.map(|l| _mm256_loadu_pd(l.as_ptr()));
                assert_eq!(registers(a, b, x, y), vectors(a, b, x, y), "{lanes:?}");
            }
        }
    }
}
