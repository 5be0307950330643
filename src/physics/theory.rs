//! Known results for hard disks that the engine sizes itself by and the tests check against:
//! Henderson's equation of state and the Enskog mean free path it gives.

/// Henderson's equation of state for hard disks, `Z = (1 + φ²/8)/(1 − φ)²`.
pub fn henderson_z(phi: f64) -> f64 {
    (1.0 + phi * phi / 8.0) / ((1.0 - phi) * (1.0 - phi))
}

/// Mean free path of hard disks of radius `a` at packing `phi` (Enskog): `λ = 1/(2√2 n σ g(σ))`,
/// `σ = 2a`, `n σ² = 4φ/π`, with the contact value of the pair correlation from Henderson's
/// equation of state, `Z = 1 + 2φ g(σ)` ([`henderson_z`]: `g(σ) = (1 − 7φ/16)/(1 − φ)²`).
/// 2.4σ at φ = 0.1, 0.52σ at 0.3, 0.05σ at 0.7.
pub fn mean_free_path(a: f64, phi: f64) -> f64 {
    let phi = phi.clamp(1e-3, 0.9);
    let n_sigma2 = 4.0 * phi / std::f64::consts::PI;
    let contact = (henderson_z(phi) - 1.0) / (2.0 * phi);
    2.0 * a / (2.0 * std::f64::consts::SQRT_2 * n_sigma2 * contact)
}

/// The ratio `R = T_rot/T_tr` of the homogeneous cooling state of rough disks in 2D with
/// normal restitution `e`, constant tangential restitution `beta` and inertia factor `q`, in
/// kinetic theory with molecular chaos (Huthmann & Zippelius 1997; Luding, Huthmann, McNamara
/// & Zippelius 1998; derived for disks on the book's physics page):
/// `dT_tr/dt = G(−A T_tr + B T_rot)`, `dT_rot/dt = 2G(B T_tr − C T_rot)` with
/// `η = q(1 + β)/(2(1 + q))`, `A = (1 − e²)/2 + η(1 − η)`, `B = η²/q`, `C = (η/q)(1 − η/q)`;
/// R is the positive root of `B R² + (2C − A) R − 2B = 0`.
pub fn rough_cooling_ratio(e: f64, beta: f64, q: f64) -> f64 {
    let eta = q * (1.0 + beta) / (2.0 * (1.0 + q));
    let a = 0.5 * (1.0 - e * e) + eta * (1.0 - eta);
    let b = eta * eta / q;
    let c = eta / q * (1.0 - eta / q);
    let k = a - 2.0 * c;
    (k + (k * k + 8.0 * b * b).sqrt()) / (2.0 * b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_elastic_perfectly_rough_gas_has_equal_temperatures() {
        for q in [0.25, 0.5, 1.0] {
            assert!((rough_cooling_ratio(1.0, 1.0, q) - 1.0).abs() < 1e-14);
        }
        // e = 0.9, β = 0, q = ½: η = 1/6, A = 0.095 + 5/36, B = 1/18, C = 2/9.
        let (a, b, c) = (0.095 + 5.0 / 36.0, 1.0 / 18.0, 2.0 / 9.0);
        let r = rough_cooling_ratio(0.9, 0.0, 0.5);
        assert!((b * r * r + (2.0 * c - a) * r - 2.0 * b).abs() < 1e-15);
        assert!((r - 0.4695).abs() < 1e-3, "{r}");
    }

    #[test]
    fn the_mean_free_path_is_enskogs() {
        // σ = 1: 0.522 at φ = 0.3 (n σ² = 1.2/π, g(σ) = 0.86875/0.49).
        let n = 1.2 / std::f64::consts::PI;
        let g = (1.0 - 2.1 / 16.0) / 0.49;
        let expected = 1.0 / (2.0 * std::f64::consts::SQRT_2 * n * g);
        assert!((mean_free_path(0.5, 0.3) - expected).abs() < 1e-12 * expected);
        assert!(mean_free_path(0.5, 0.1) > 2.0 && mean_free_path(0.5, 0.7) < 0.06);
        // At every packing, with Henderson's contact value g(σ) = (1 − 7φ/16)/(1 − φ)².
        for phi in [0.1, 0.5, 0.7] {
            let n = 4.0 * phi / std::f64::consts::PI;
            let g = (1.0 - 7.0 * phi / 16.0) / ((1.0 - phi) * (1.0 - phi));
            let expected = 1.0 / (2.0 * std::f64::consts::SQRT_2 * n * g);
            assert!((mean_free_path(0.5, phi) - expected).abs() < 1e-12 * expected);
        }
    }

    #[test]
    fn hendersons_equation_of_state_at_known_packings() {
        assert_eq!(henderson_z(0.0), 1.0);
        // (1 + 0.09/8)/0.49 and (1 + 0.49/8)/0.09.
        assert!((henderson_z(0.3) - 2.063_775_510_204_082).abs() < 1e-12);
        assert!((henderson_z(0.7) - 11.791_666_666_666_668).abs() < 1e-12);
    }
}
