//! Bulk (tube-average) porosity correlations, ε(N).
//!
//! Each function takes N as its correlation defines it (see its doc and
//! [`BulkCorrelation::n_definition`]) and evaluates the formula for any
//! N > 0 where the formula is defined, inside or outside its validity
//! range: deciding what is valid is the caller's job, with
//! [`BulkCorrelation::n_range`]. The values in the reference table
//! (`tests/fixtures/bulk_porosity_correlations.csv`) are reproduced to its
//! printed precision by `tests/tables.rs`.

use crate::{Grade, NDefinition, Range, Shape};

/// One bulk porosity correlation and what is known about it.
#[derive(Debug)]
pub struct BulkCorrelation {
    /// Canonical name (several shapes may share one, e.g. `dixon-1988`).
    pub name: &'static str,
    /// The shape it was made for.
    pub shape: Shape,
    /// Human label for plots and reports.
    pub label: &'static str,
    /// Where it comes from.
    pub citation: &'static str,
    /// How sure the coefficients are.
    pub grade: Grade,
    /// How its N is defined.
    pub n_definition: NDefinition,
    /// Where it is valid, in its own N.
    pub n_range: Range,
    /// Caveats printed with every score.
    pub note: &'static str,
    /// The formula.
    pub formula: Formula,
}

/// How a bulk correlation computes ε.
#[derive(Debug)]
pub enum Formula {
    /// ε(N), N as the correlation defines it.
    OfN(fn(f64) -> f64),
    /// [`ring_envelope_dixon`]: ε(N_env, di/do).
    RingEnvelope,
    /// [`benyahia_oneill_2005_sphericity`]: ε(N, φ).
    Sphericity,
}

/// Pellet properties some formulas need besides N.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Extras {
    /// Rings: inner over outer diameter.
    pub di_over_do: Option<f64>,
    /// Wadell sphericity φ (1 for spheres).
    pub sphericity: Option<f64>,
}

impl BulkCorrelation {
    /// ε at `n` (its own N); the ring estimate needs di/do and the
    /// sphericity form φ: `None` without them.
    pub fn predict(&self, n: f64, extras: &Extras) -> Option<f64> {
        match self.formula {
            Formula::OfN(f) => Some(f(n)),
            Formula::RingEnvelope => extras.di_over_do.map(|r| ring_envelope_dixon(n, r)),
            Formula::Sphericity => extras.sphericity.map(|phi| benyahia_oneill_2005_sphericity(n, phi)),
        }
    }
}

/// Every bulk correlation, in the order reports list them.
pub static BULK: &[BulkCorrelation] = &[
    BulkCorrelation {
        name: "dixon-1988",
        shape: Shape::Sphere,
        label: "Dixon (1988), spheres",
        citation: "Dixon A.G. (1988) Can. J. Chem. Eng. 66:705",
        grade: Grade::A,
        n_definition: NDefinition::DOverDp,
        n_range: Range::from(1.0),
        note: "",
        formula: Formula::OfN(dixon_1988_spheres),
    },
    BulkCorrelation {
        name: "foumeny-1993",
        shape: Shape::Sphere,
        label: "Foumeny et al. (1993)",
        citation: "Foumeny E.A. et al. (1993) Int. J. Heat Mass Transfer 36:536",
        grade: Grade::B,
        n_definition: NDefinition::DOverDp,
        n_range: Range::between(1.87, 23.5),
        note: "",
        formula: Formula::OfN(foumeny_1993_spheres),
    },
    BulkCorrelation {
        name: "benyahia-oneill-2005",
        shape: Shape::Sphere,
        label: "Benyahia & O'Neill (2005), spheres",
        citation: "Benyahia F., O'Neill K.E. (2005) Part. Sci. Technol. 23:169",
        grade: Grade::B,
        n_definition: NDefinition::DOverDp,
        n_range: Range::between(1.5, 50.0),
        note: "",
        formula: Formula::OfN(benyahia_oneill_2005_spheres),
    },
    BulkCorrelation {
        name: "cheng-2011",
        shape: Shape::Sphere,
        label: "Cheng (2011)",
        citation: "Cheng N.-S. (2011) Powder Technol. 210:261",
        grade: Grade::B,
        n_definition: NDefinition::DOverDp,
        n_range: Range::from(1.0),
        note: "",
        formula: Formula::OfN(cheng_2011_spheres),
    },
    BulkCorrelation {
        name: "sato-1973",
        shape: Shape::Sphere,
        label: "Sato et al. (1973)",
        citation: "Sato Y. et al. (1973) J. Chem. Eng. Japan",
        grade: Grade::B,
        n_definition: NDefinition::DOverDp,
        n_range: Range::from(2.0),
        note: "validity range not stated in the sources at hand; N ≥ 2 is the reference table's domain",
        formula: Formula::OfN(sato_1973_spheres),
    },
    BulkCorrelation {
        name: "zou-yu-1995",
        shape: Shape::Sphere,
        label: "Zou & Yu (1995), dense",
        citation: "Zou R.P., Yu A.B. (1995) Chem. Eng. Sci. 50:1504",
        grade: Grade::C,
        n_definition: NDefinition::DOverDp,
        n_range: Range::from(4.0),
        note: "dense packing",
        formula: Formula::OfN(zou_yu_1995_spheres_dense),
    },
    BulkCorrelation {
        name: "zou-yu-1995-loose",
        shape: Shape::Sphere,
        label: "Zou & Yu (1995), loose",
        citation: "Zou R.P., Yu A.B. (1995) Chem. Eng. Sci. 50:1504",
        grade: Grade::C,
        n_definition: NDefinition::DOverDp,
        n_range: Range::from(4.0),
        note: "loose packing",
        formula: Formula::OfN(zou_yu_1995_spheres_loose),
    },
    BulkCorrelation {
        name: "pushnov-2006",
        shape: Shape::Sphere,
        label: "Pushnov (2006), spheres",
        citation: "Pushnov A.S. (2006) Chem. Pet. Eng. 42",
        grade: Grade::C,
        n_definition: NDefinition::DOverDp,
        n_range: Range::from(2.0),
        note: "form and coefficients inferred from the reference table, not from the paper",
        formula: Formula::OfN(pushnov_2006_spheres),
    },
    BulkCorrelation {
        name: "jeschar-1975",
        shape: Shape::Sphere,
        label: "Jeschar (1975)",
        citation: "Jeschar R. (1975) Arch. Eisenhüttenwes. 46",
        grade: Grade::C,
        n_definition: NDefinition::DOverDp,
        n_range: Range::from(2.0),
        note: "form and coefficients inferred from the reference table, not from the paper",
        formula: Formula::OfN(jeschar_1975_spheres),
    },
    BulkCorrelation {
        name: "dixon-1988",
        shape: Shape::Cylinder,
        label: "Dixon (1988), cylinders",
        citation: "Dixon A.G. (1988) Can. J. Chem. Eng. 66:705",
        grade: Grade::B,
        n_definition: NDefinition::DOverDpv,
        n_range: Range::from(1.0),
        note: "equilateral solid cylinders",
        formula: Formula::OfN(dixon_1988_cylinders),
    },
    BulkCorrelation {
        name: "benyahia-oneill-2005",
        shape: Shape::Cylinder,
        label: "Benyahia & O'Neill (2005), cylinders",
        citation: "Benyahia F., O'Neill K.E. (2005) Part. Sci. Technol. 23:169",
        grade: Grade::B,
        n_definition: NDefinition::DOverDpv,
        n_range: Range::between(1.7, 26.3),
        note: "equilateral solid cylinders",
        formula: Formula::OfN(benyahia_oneill_2005_cylinders),
    },
    BulkCorrelation {
        name: "pushnov-2006",
        shape: Shape::Cylinder,
        label: "Pushnov (2006), cylinders",
        citation: "Pushnov A.S. (2006) Chem. Pet. Eng. 42",
        grade: Grade::C,
        n_definition: NDefinition::DOverDp,
        n_range: Range::from(2.0),
        note: "form, coefficients and N definition inferred from the reference table, not from the paper",
        formula: Formula::OfN(pushnov_2006_cylinders),
    },
    BulkCorrelation {
        name: "benyahia-oneill-2005-sphericity",
        shape: Shape::Sphere,
        label: "Benyahia & O'Neill (2005), sphericity form",
        citation: "Benyahia F., O'Neill K.E. (2005) Part. Sci. Technol. 23:169",
        grade: Grade::B,
        n_definition: NDefinition::DOverDpv,
        n_range: Range::between(1.5, 50.0),
        note: "any shape through the Wadell sphericity φ, valid for 0.42 < φ < 1 (so not for spheres)",
        formula: Formula::Sphericity,
    },
    BulkCorrelation {
        name: "benyahia-oneill-2005-sphericity",
        shape: Shape::Cylinder,
        label: "Benyahia & O'Neill (2005), sphericity form",
        citation: "Benyahia F., O'Neill K.E. (2005) Part. Sci. Technol. 23:169",
        grade: Grade::B,
        n_definition: NDefinition::DOverDpv,
        n_range: Range::between(1.5, 50.0),
        note: "any shape through the Wadell sphericity φ, valid for 0.42 < φ < 1 (so not for spheres)",
        formula: Formula::Sphericity,
    },
    BulkCorrelation {
        name: "benyahia-oneill-2005-sphericity",
        shape: Shape::Ring,
        label: "Benyahia & O'Neill (2005), sphericity form",
        citation: "Benyahia F., O'Neill K.E. (2005) Part. Sci. Technol. 23:169",
        grade: Grade::B,
        n_definition: NDefinition::DOverDpv,
        n_range: Range::between(1.5, 50.0),
        note: "any shape through the Wadell sphericity φ, valid for 0.42 < φ < 1 (so not for spheres)",
        formula: Formula::Sphericity,
    },
    BulkCorrelation {
        name: "ring-envelope-dixon",
        shape: Shape::Ring,
        label: "rings: Dixon cylinder envelope + hole (approximation, not literature)",
        citation: "packbed's approximation from Dixon (1988) cylinders; not a literature correlation",
        grade: Grade::C,
        n_definition: NDefinition::DOverDpvEnvelope,
        n_range: Range::from(1.0),
        note:
            "approximation of ours, not literature: ε = 1 − (1 − ε_Dixon,cyl(N_env))(1 − (di/do)²), di/do from the bed",
        formula: Formula::RingEnvelope,
    },
];

/// Dixon (1988) for spheres. Grade **A**.
///
/// Dixon A.G. (1988) "Correlations for wall and particle shape effects on
/// fixed bed bulk voidage", Can. J. Chem. Eng. 66:705. N = D/dp, x = 1/N;
/// valid for every N ≥ 1 (the last branch is exact for a single file):
/// x ≤ 0.5: ε = 0.4 + 0.05x + 0.412x²; 0.5 ≤ x ≤ 0.536: ε = 0.528 +
/// 2.464(x − 0.5); x ≥ 0.536: ε = 1 − 0.667x³(2x − 1)^(−1/2).
pub fn dixon_1988_spheres(n: f64) -> f64 {
    let x = 1.0 / n;
    if x <= 0.5 {
        0.4 + 0.05 * x + 0.412 * x * x
    } else if x <= 0.536 {
        0.528 + 2.464 * (x - 0.5)
    } else {
        1.0 - 0.667 * x.powi(3) / (2.0 * x - 1.0).sqrt()
    }
}

/// Foumeny et al. (1993) for spheres. Grade **B**.
///
/// Foumeny E.A., Benyahia F., Castro J.A.A., Moallemi H.A., Roshani S.
/// (1993) Int. J. Heat Mass Transfer 36:536. N = D/dp, valid for about
/// 1.87 ≤ N ≤ 23.5: ε = 0.383 + 0.254 N^(−0.923) (0.723N − 1)^(−1/2).
pub fn foumeny_1993_spheres(n: f64) -> f64 {
    0.383 + 0.254 * n.powf(-0.923) / (0.723 * n - 1.0).sqrt()
}

/// Benyahia & O'Neill (2005) for spheres. Grade **B**.
///
/// Benyahia F., O'Neill K.E. (2005) "Enhanced voidage correlations for
/// packed beds of various particle shapes and sizes", Part. Sci. Technol.
/// 23:169. N = D/dp, valid for 1.5 < N < 50: ε = 0.390 + 1.740/(N + 1.140)².
pub fn benyahia_oneill_2005_spheres(n: f64) -> f64 {
    0.390 + 1.740 / (n + 1.140).powi(2)
}

/// Cheng (2011) for spheres. Grade **B**.
///
/// Cheng N.-S. (2011) "Wall effect on pressure drop in packed beds",
/// Powder Technol. 210:261. N = D/dp, N > 1: ε = (ε₁⁻³ + ε₂⁻³)^(−1/3),
/// ε₁ = 0.8(N − 1)^0.27, ε₂ = 0.38(1 + (N − 1)^(−1.9)).
pub fn cheng_2011_spheres(n: f64) -> f64 {
    let e1 = 0.8 * (n - 1.0).powf(0.27);
    let e2 = 0.38 * (1.0 + (n - 1.0).powf(-1.9));
    (e1.powi(-3) + e2.powi(-3)).powf(-1.0 / 3.0)
}

/// Sato et al. (1973) for spheres. Grade **B**.
///
/// Sato Y., Hirose T., Takahashi F., Toda M. (1973) J. Chem. Eng. Japan.
/// N = D/dp: ε = 0.3494 + 0.4381/N. The range is not stated in the sources
/// at hand; N ≥ 2 (the reference table's domain) is used.
pub fn sato_1973_spheres(n: f64) -> f64 {
    0.3494 + 0.4381 / n
}

/// Zou & Yu (1995), dense random packing of spheres. Grade **C**.
///
/// Zou R.P., Yu A.B. (1995) Chem. Eng. Sci. 50:1504. N = D/dp, N ≳ 4:
/// ε = 0.372 + 0.002(e^(15.306/N) − 1).
pub fn zou_yu_1995_spheres_dense(n: f64) -> f64 {
    0.372 + 0.002 * ((15.306 / n).exp() - 1.0)
}

/// Zou & Yu (1995), loose random packing of spheres. Grade **C**.
///
/// Zou R.P., Yu A.B. (1995) Chem. Eng. Sci. 50:1504. N = D/dp, N ≳ 4:
/// ε = 0.400 + 0.010(e^(10.686/N) − 1). Not in the reference table.
pub fn zou_yu_1995_spheres_loose(n: f64) -> f64 {
    0.400 + 0.010 * ((10.686 / n).exp() - 1.0)
}

/// Pushnov (2006) for spheres. Grade **C**.
///
/// Pushnov A.S. (2006) Chem. Pet. Eng. 42. N = D/dp, ε = 1/N² + 0.375.
/// The reference table has this column without the formula; this form
/// reproduces it, but was not checked against the paper. N ≥ 2.
pub fn pushnov_2006_spheres(n: f64) -> f64 {
    1.0 / (n * n) + 0.375
}

/// Jeschar (1975) for spheres. Grade **C**.
///
/// Jeschar R. (1975) Arch. Eisenhüttenwes. 46. N = D/dp, ε = 0.375 + 0.34/N.
/// Inferred from the reference table's column, not checked against the
/// paper. N ≥ 2.
pub fn jeschar_1975_spheres(n: f64) -> f64 {
    0.375 + 0.34 / n
}

/// Dixon (1988) for equilateral solid cylinders. Grade **B**.
///
/// Dixon A.G. (1988) Can. J. Chem. Eng. 66:705. N = D/dpv, x = 1/N, every
/// N ≥ 1: x ≤ 0.6: ε = 0.36 + 0.10x + 0.70x²; 0.6 ≤ x ≤ 0.7:
/// ε = 0.677 − 9(x − 0.625)²; x ≥ 0.7: ε = 1 − 0.763x² (exact for a single
/// file of cylinders).
pub fn dixon_1988_cylinders(n: f64) -> f64 {
    let x = 1.0 / n;
    if x <= 0.6 {
        0.36 + 0.10 * x + 0.70 * x * x
    } else if x <= 0.7 {
        0.677 - 9.0 * (x - 0.625).powi(2)
    } else {
        1.0 - 0.763 * x * x
    }
}

/// Benyahia & O'Neill (2005) for equilateral solid cylinders. Grade **B**.
///
/// Benyahia F., O'Neill K.E. (2005) Part. Sci. Technol. 23:169. N = D/dpv,
/// valid for 1.7 < N < 26.3: ε = 0.373 + 1.703/(N + 0.611)².
pub fn benyahia_oneill_2005_cylinders(n: f64) -> f64 {
    0.373 + 1.703 / (n + 0.611).powi(2)
}

/// Benyahia & O'Neill (2005) for any shape, through the Wadell sphericity
/// φ. Grade **B**.
///
/// Benyahia F., O'Neill K.E. (2005) Part. Sci. Technol. 23:169. N = D/dpv,
/// valid for 1.5 < N < 50 and 0.42 < φ < 1: ε = 0.1504 + 0.2024/φ +
/// 1.0814/(N + 0.1226)² (φ = 0.874 for an equilateral cylinder).
pub fn benyahia_oneill_2005_sphericity(n: f64, sphericity: f64) -> f64 {
    0.1504 + 0.2024 / sphericity + 1.0814 / (n + 0.1226).powi(2)
}

/// Pushnov (2006) for cylinders. Grade **C**.
///
/// Pushnov A.S. (2006) Chem. Pet. Eng. 42. ε = 0.9198/N² + 0.3414 with
/// N = D/dp as far as we know. Inferred from the reference table's column,
/// not checked against the paper. N ≥ 2.
pub fn pushnov_2006_cylinders(n: f64) -> f64 {
    0.9198 / (n * n) + 0.3414
}

/// Raschig rings as a solid envelope plus a hole — an approximation of
/// packbed's, **not literature** (grade **C**).
///
/// No ring correlation could be verified. The ring's envelope (the solid
/// cylinder around it) is treated with [`dixon_1988_cylinders`] at
/// N_env = D/dpv(envelope) and the hole is added as void:
/// ε = 1 − (1 − ε_cyl(N_env))·(1 − (di/do)²).
pub fn ring_envelope_dixon(n_envelope: f64, di_over_do: f64) -> f64 {
    1.0 - (1.0 - dixon_1988_cylinders(n_envelope)) * (1.0 - di_over_do * di_over_do)
}

/// [`ring_envelope_dixon`] for di/do = 0.5, the reference table's ring.
pub fn ring_envelope_dixon_half(n_envelope: f64) -> f64 {
    ring_envelope_dixon(n_envelope, 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dixon_spheres_hits_the_readme_values_and_joins_its_branches() {
        assert!((dixon_1988_spheres(5.0) - 0.4265).abs() < 5e-5);
        assert!((dixon_1988_spheres(10.0) - 0.4091).abs() < 5e-5);
        // Single sphere in a tube of its own diameter: 1 − 2/3 (0.667 rounded).
        assert!((dixon_1988_spheres(1.0) - 0.333).abs() < 1e-12);
    }

    #[test]
    fn dixon_cylinders_single_file_limit_is_exact() {
        // One equilateral cylinder per layer in a tube of diameter dpv·N:
        // at N = 1 the envelope fills 1 − 0.763 of the tube.
        assert!((dixon_1988_cylinders(1.0) - 0.237).abs() < 1e-12);
    }

    #[test]
    fn sphericity_form_at_equilateral_cylinder_is_close_to_the_cylinder_fit() {
        let n = 6.0;
        let a = benyahia_oneill_2005_sphericity(n, 0.874);
        let b = benyahia_oneill_2005_cylinders(n);
        assert!((a - b).abs() < 0.01, "{a} vs {b}");
    }
}
