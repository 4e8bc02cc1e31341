//! Finding correlations by name.
//!
//! Canonical names are `author-year` in lowercase with hyphens
//! (`de-klerk-2003`); aliases drop the year (`de-klerk`) or, for bulk
//! correlations with one name for several shapes, pin the shape
//! (`dixon-spheres`, `dixon-cylinders`). Names are case-insensitive and
//! `_` counts as `-`.

use crate::bulk::{BulkCorrelation, Formula, BULK};
use crate::radial::{RadialCorrelation, RADIAL};
use crate::{RefError, Shape};

/// A resolved reference.
#[derive(Clone, Copy, Debug)]
pub enum Reference {
    /// A bulk porosity correlation.
    Bulk(&'static BulkCorrelation),
    /// A radial void-fraction correlation.
    Radial(&'static RadialCorrelation),
}

impl Reference {
    /// Its canonical name.
    pub fn name(&self) -> &'static str {
        match self {
            Reference::Bulk(c) => c.name,
            Reference::Radial(c) => c.name,
        }
    }
}

/// Aliases: (alias, canonical name, shape pinned by the alias).
const ALIASES: &[(&str, &str, Option<Shape>)] = &[
    ("de-klerk", "de-klerk-2003", None),
    ("mueller", "mueller-1992", None),
    ("cohen-metzner", "cohen-metzner-1981", None),
    ("martin", "martin-1978", None),
    ("bey-eigenberger", "bey-eigenberger-1997", None),
    ("dixon", "dixon-1988", None),
    ("dixon-spheres", "dixon-1988", Some(Shape::Sphere)),
    ("dixon-cylinders", "dixon-1988", Some(Shape::Cylinder)),
    ("foumeny", "foumeny-1993", None),
    ("benyahia-oneill", "benyahia-oneill-2005", None),
    ("benyahia-oneill-spheres", "benyahia-oneill-2005", Some(Shape::Sphere)),
    ("benyahia-oneill-cylinders", "benyahia-oneill-2005", Some(Shape::Cylinder)),
    ("benyahia-oneill-sphericity", "benyahia-oneill-2005-sphericity", None),
    ("cheng", "cheng-2011", None),
    ("sato", "sato-1973", None),
    ("zou-yu", "zou-yu-1995", None),
    ("pushnov", "pushnov-2006", None),
    ("jeschar", "jeschar-1975", None),
    ("ring-envelope", "ring-envelope-dixon", None),
];

/// Finds a reference by name or alias, for a bed of `shape`.
///
/// A bulk name shared by several shapes (`dixon-1988`) resolves to the
/// variant for `shape`; if it has none, to its first variant (the caller
/// then flags the score, as the correlation is for another shape).
pub fn resolve(name: &str, shape: Shape) -> Result<Reference, RefError> {
    let key = name.trim().to_ascii_lowercase().replace('_', "-");
    let (canonical, pinned) = match ALIASES.iter().find(|(alias, _, _)| *alias == key) {
        Some((_, canonical, pinned)) => (canonical.to_string(), *pinned),
        None => (key, None),
    };
    if let Some(c) = RADIAL.iter().find(|c| c.name == canonical) {
        return Ok(Reference::Radial(c));
    }
    let want = pinned.unwrap_or(shape);
    let mut variants = BULK.iter().filter(|c| c.name == canonical).peekable();
    let first = variants.peek().copied();
    if let Some(c) = variants.find(|c| c.shape == want).or(first) {
        return Ok(Reference::Bulk(c));
    }
    Err(RefError::UnknownReference { name: name.trim().to_string(), known: canonical_names().join(", ") })
}

/// Every canonical name, radial first, without repeats.
pub fn canonical_names() -> Vec<&'static str> {
    let mut names: Vec<&'static str> = RADIAL.iter().map(|c| c.name).collect();
    for c in BULK {
        if !names.contains(&c.name) {
            names.push(c.name);
        }
    }
    names
}

/// The aliases of a canonical name.
pub fn aliases_of(canonical: &str) -> Vec<&'static str> {
    ALIASES.iter().filter(|(_, c, _)| *c == canonical).map(|(a, _, _)| *a).collect()
}

/// The default set for a bed of `shape`: every radial correlation and
/// every bulk one made for that shape — except the sphericity form for
/// spheres, whose range (0.42 < φ < 1) excludes them.
pub fn defaults(shape: Shape) -> Vec<Reference> {
    let mut refs: Vec<Reference> = RADIAL.iter().map(Reference::Radial).collect();
    refs.extend(
        BULK.iter()
            .filter(|c| c.shape == shape)
            .filter(|c| !(shape == Shape::Sphere && matches!(c.formula, Formula::Sphericity)))
            .map(Reference::Bulk),
    );
    refs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aliases_and_canonical_names_resolve_to_the_same_correlation() {
        for (alias, canonical, _) in ALIASES {
            let a = resolve(alias, Shape::Sphere).unwrap();
            assert_eq!(a.name(), *canonical);
        }
        assert_eq!(resolve("De_Klerk", Shape::Sphere).unwrap().name(), "de-klerk-2003");
    }

    #[test]
    fn shared_bulk_names_follow_the_bed_shape_unless_pinned() {
        let Reference::Bulk(c) = resolve("dixon-1988", Shape::Cylinder).unwrap() else { panic!() };
        assert_eq!(c.shape, Shape::Cylinder);
        let Reference::Bulk(c) = resolve("dixon-spheres", Shape::Cylinder).unwrap() else { panic!() };
        assert_eq!(c.shape, Shape::Sphere);
        // Foumeny has spheres only: resolved anyway, the caller flags it.
        let Reference::Bulk(c) = resolve("foumeny", Shape::Ring).unwrap() else { panic!() };
        assert_eq!(c.shape, Shape::Sphere);
    }

    #[test]
    fn unknown_names_list_the_known_ones() {
        let e = resolve("nope-2020", Shape::Sphere).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("\"nope-2020\"") && msg.contains("mueller-1992"), "{msg}");
    }

    #[test]
    fn every_canonical_name_is_unique_per_shape() {
        for (i, a) in BULK.iter().enumerate() {
            for b in &BULK[i + 1..] {
                assert!(!(a.name == b.name && a.shape == b.shape), "{}", a.name);
            }
        }
    }
}
