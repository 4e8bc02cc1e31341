//! Radial void-fraction correlations for tubes packed with spheres.
//!
//! The wall coordinate is z = (R − r)/dp: 0 at the wall, growing inwards.
//! Every correlation here was fitted to sphere beds; applied to other
//! shapes it is computed but flagged (see [`crate::scoring`]). The values
//! of the reference table (`tests/fixtures/radial_profile_correlations.csv`)
//! are reproduced by `tests/tables.rs`.
//!
//! Most forms take ε_b, the voidage far from the wall — *not* the tube
//! average: feeding the tube average in biases the whole profile upward by
//! 0.03–0.06 at N = 5–10. [`crate::scoring::fit_eps_b`] finds the ε_b
//! whose profile has the bed's bulk porosity as cross-section mean.
//! Mueller's form carries its own ε_b(N).

use crate::{bessel_j0, Grade, Range};

/// Where a profile correlation gets its ε_b.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EpsBSource {
    /// ε_b is a parameter of the formula (given or fitted by the caller).
    Parameter,
    /// The formula computes its own ε_b from N (Mueller).
    OwnFromN,
}

/// One radial correlation and what is known about it.
#[derive(Debug)]
pub struct RadialCorrelation {
    /// Canonical name.
    pub name: &'static str,
    /// Human label for plots and reports.
    pub label: &'static str,
    /// Where it comes from.
    pub citation: &'static str,
    /// How sure the coefficients are.
    pub grade: Grade,
    /// Where it is valid in N = D/dp (spheres).
    pub n_range: Range,
    /// Where ε_b comes from.
    pub eps_b: EpsBSource,
    /// The formula ε(z, N, ε_b); z = (R − r)/dp. Forms that do not use N or
    /// ε_b ignore them.
    pub eval: fn(f64, f64, f64) -> f64,
}

/// Every radial correlation, in the order reports list them.
pub static RADIAL: &[RadialCorrelation] = &[
    RadialCorrelation {
        name: "de-klerk-2003",
        label: "de Klerk (2003)",
        citation: "de Klerk A. (2003) AIChE J. 49:2022",
        grade: Grade::B,
        n_range: Range::from(1.0),
        eps_b: EpsBSource::Parameter,
        eval: |z, _, eps_b| de_klerk_2003(z, eps_b),
    },
    RadialCorrelation {
        name: "mueller-1992",
        label: "Mueller (1992)",
        citation: "Mueller G.E. (1992) Powder Technol. 72:269",
        grade: Grade::B,
        n_range: Range::from(2.02),
        eps_b: EpsBSource::OwnFromN,
        eval: |z, n, _| mueller_1992(z, n),
    },
    RadialCorrelation {
        name: "cohen-metzner-1981",
        label: "Cohen & Metzner (1981)",
        citation: "Cohen Y., Metzner A.B. (1981) AIChE J. 27:705",
        grade: Grade::B,
        n_range: Range::from(1.0),
        eps_b: EpsBSource::Parameter,
        eval: |z, _, eps_b| cohen_metzner_1981(z, eps_b),
    },
    RadialCorrelation {
        name: "martin-1978",
        label: "Martin (1978)",
        citation: "Martin H. (1978) Chem. Eng. Sci. 33:913",
        grade: Grade::C,
        n_range: Range::from(1.0),
        eps_b: EpsBSource::Parameter,
        eval: |z, _, eps_b| martin_1978(z, eps_b, MARTIN_EPS_MIN),
    },
    RadialCorrelation {
        name: "bey-eigenberger-1997",
        label: "Bey & Eigenberger (1997)",
        citation: "Bey O., Eigenberger G. (1997) Chem. Eng. Sci. 52:1365",
        grade: Grade::C,
        n_range: Range::from(1.0),
        eps_b: EpsBSource::Parameter,
        eval: |z, _, eps_b| bey_eigenberger_1997(z, eps_b, BEY_EIGENBERGER_EPS_MIN),
    },
];

/// de Klerk (2003). Grade **B**.
///
/// de Klerk A. (2003) "Voidage variation in packed beds at small column to
/// particle diameter ratio", AIChE J. 49:2022. Spheres, z = (R − r)/dp,
/// every z ≥ 0: z ≤ 0.637: ε = 2.14z² − 2.53z + 1; z > 0.637: ε = ε_b +
/// 0.29 e^(−0.6z) cos(2.3π(z − 0.16)) + 0.15 e^(−0.9z).
pub fn de_klerk_2003(z: f64, eps_b: f64) -> f64 {
    if z <= 0.637 {
        2.14 * z * z - 2.53 * z + 1.0
    } else {
        eps_b + 0.29 * (-0.6 * z).exp() * (2.3 * std::f64::consts::PI * (z - 0.16)).cos() + 0.15 * (-0.9 * z).exp()
    }
}

/// Mueller (1992). Grade **B** (form confirmed, coefficients recalled).
///
/// Mueller G.E. (1992) "Radial void fraction distributions in randomly
/// packed fixed beds of uniformly sized spheres in cylindrical containers",
/// Powder Technol. 72:269. Spheres, N = D/dp ≥ 2.02, z = (R − r)/dp:
/// ε = ε_b + (1 − ε_b) J₀(a z) e^(−b z), a = 7.45 − 3.15/N (2.02 ≤ N ≤ 13),
/// a = 7.45 − 11.25/N (N > 13), b = 0.315 − 0.725/N, with its own
/// ε_b = 0.365 + 0.220/N.
pub fn mueller_1992(z: f64, n: f64) -> f64 {
    let a = if n <= 13.0 { 7.45 - 3.15 / n } else { 7.45 - 11.25 / n };
    let b = 0.315 - 0.725 / n;
    let eps_b = mueller_1992_eps_b(n);
    eps_b + (1.0 - eps_b) * bessel_j0(a * z) * (-b * z).exp()
}

/// Mueller's (1992) own bulk voidage, ε_b = 0.365 + 0.220/N (N = D/dp).
pub fn mueller_1992_eps_b(n: f64) -> f64 {
    0.365 + 0.220 / n
}

/// Cohen & Metzner (1981). Grade **B**.
///
/// Cohen Y., Metzner A.B. (1981) "Wall effects in laminar flow of fluids
/// through packed beds", AIChE J. 27:705. Spheres, z = (R − r)/dp:
/// z ≤ 0.25: (1 − ε)/(1 − ε_b) = 4.5(z − 7z²/9); 0.25 < z < 8:
/// (ε − ε_b)/(1 − ε_b) = 0.3463 e^(−0.4273z) cos((2.4509z − 2.2011)π);
/// z ≥ 8: ε = ε_b.
pub fn cohen_metzner_1981(z: f64, eps_b: f64) -> f64 {
    if z <= 0.25 {
        1.0 - (1.0 - eps_b) * 4.5 * (z - 7.0 * z * z / 9.0)
    } else if z < 8.0 {
        eps_b + (1.0 - eps_b) * 0.3463 * (-0.4273 * z).exp() * ((2.4509 * z - 2.2011) * std::f64::consts::PI).cos()
    } else {
        eps_b
    }
}

/// ε_min of Martin's form, as in the reference table.
pub const MARTIN_EPS_MIN: f64 = 0.23;

/// Martin (1978). Grade **C** (form as in the reference table).
///
/// Martin H. (1978) Chem. Eng. Sci. 33:913. Spheres, with z′ = 2z − 1:
/// z′ ≤ 0: ε = ε_min + (1 − ε_min) z′²; z′ > 0: ε = ε_b + (ε_min − ε_b)
/// e^(−z′/4) cos(π z′/0.816). The table uses ε_min = 0.23.
pub fn martin_1978(z: f64, eps_b: f64, eps_min: f64) -> f64 {
    let zp = 2.0 * z - 1.0;
    if zp <= 0.0 {
        eps_min + (1.0 - eps_min) * zp * zp
    } else {
        eps_b + (eps_min - eps_b) * (-zp / 4.0).exp() * (std::f64::consts::PI * zp / 0.816).cos()
    }
}

/// ε_min of Bey & Eigenberger's form, as in the reference table.
pub const BEY_EIGENBERGER_EPS_MIN: f64 = 0.24;

/// Bey & Eigenberger (1997). Grade **C** (form as in the reference table).
///
/// Bey O., Eigenberger G. (1997) Chem. Eng. Sci. 52:1365. Spheres, with
/// z′ = 2z − 1: z′ ≤ 0: ε = ε_min + (1 − ε_min) z′²; z′ > 0: ε = ε_b +
/// (ε_min − ε_b) e^(−z′/2) cos(π z′/0.876). The table uses ε_min = 0.24.
pub fn bey_eigenberger_1997(z: f64, eps_b: f64, eps_min: f64) -> f64 {
    let zp = 2.0 * z - 1.0;
    if zp <= 0.0 {
        eps_min + (1.0 - eps_min) * zp * zp
    } else {
        eps_b + (eps_min - eps_b) * (-zp / 2.0).exp() * (std::f64::consts::PI * zp / 0.876).cos()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_form_is_one_at_the_wall() {
        for c in RADIAL {
            assert!(((c.eval)(0.0, 7.0, 0.39) - 1.0).abs() < 1e-12, "{}", c.name);
        }
    }

    #[test]
    fn cohen_metzner_tends_to_eps_b_far_from_the_wall() {
        assert_eq!(cohen_metzner_1981(9.0, 0.37), 0.37);
    }

    #[test]
    fn mueller_eps_b_is_its_own() {
        assert!((mueller_1992_eps_b(10.0) - 0.387).abs() < 1e-15);
    }
}
