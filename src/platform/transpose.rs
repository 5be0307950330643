//! A 4×4 block of `f64` turned from rows to columns in AVX2 registers: four disks' states, one per
//! register, become one quantity of the four disks per register, and back (the turn is its own
//! inverse). The vector loops of contact dynamics load and store their disks this way.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// Rows `r[l] = (a_l, b_l, c_l, d_l)` to columns `(a_0..a_3), (b_0..b_3), (c_0..c_3), (d_0..d_3)`.
///
/// # Safety
///
/// Only where the processor has AVX2.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline]
pub unsafe fn transpose(r: [__m256d; 4]) -> [__m256d; 4] {
    let lo01 = _mm256_unpacklo_pd(r[0], r[1]); // a0 a1 c0 c1
    let hi01 = _mm256_unpackhi_pd(r[0], r[1]); // b0 b1 d0 d1
    let lo23 = _mm256_unpacklo_pd(r[2], r[3]);
    let hi23 = _mm256_unpackhi_pd(r[2], r[3]);
    [
        _mm256_permute2f128_pd::<0x20>(lo01, lo23),
        _mm256_permute2f128_pd::<0x20>(hi01, hi23),
        _mm256_permute2f128_pd::<0x31>(lo01, lo23),
        _mm256_permute2f128_pd::<0x31>(hi01, hi23),
    ]
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    #[test]
    fn rows_become_columns_and_back() {
        if !crate::platform::cpu::Lanes::found().avx2() {
            eprintln!("no AVX2 here: nothing to turn");
            return;
        }
        let rows: [[f64; 4]; 4] =
            std::array::from_fn(|l| std::array::from_fn(|k| (10 * l + k) as f64));
        // SAFETY: the processor has AVX2.
        unsafe {
            let r = rows.map(|row| _mm256_loadu_pd(row.as_ptr()));
            let c = transpose(r);
            for (k, column) in c.iter().enumerate() {
                let mut got = [0.0; 4];
                _mm256_storeu_pd(got.as_mut_ptr(), *column);
                assert_eq!(got, std::array::from_fn(|l| rows[l][k]), "column {k}");
            }
            let back = transpose(c);
            for (l, row) in back.iter().enumerate() {
                let mut got = [0.0; 4];
                _mm256_storeu_pd(got.as_mut_ptr(), *row);
                assert_eq!(got, rows[l], "row {l}");
            }
        }
    }
}
