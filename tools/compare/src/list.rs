//! `--list-refs`: every reference with its names, grade, range and N.

use pellet_refs::bulk::BULK;
use pellet_refs::radial::{EpsBSource, RADIAL};
use pellet_refs::registry::aliases_of;

/// The table printed by `compare --list-refs`.
pub fn table() -> String {
    let mut out = String::from("# radial void fraction, spheres, z = (R − r)/dp\n");
    out += "name\taliases\tgrade\tvalid for\tε_b\tcitation\n";
    for c in RADIAL {
        let eps_b = match c.eps_b {
            EpsBSource::Parameter => "parameter (fitted or given)",
            EpsBSource::OwnFromN => "own, from N",
        };
        out += &format!(
            "{}\t{}\t{:?}\t{} (N = D/dp)\t{eps_b}\t{}\n",
            c.name,
            aliases_of(c.name).join(","),
            c.grade,
            c.n_range.describe("N"),
            c.citation
        );
    }
    out += "\n# bulk porosity\nname\taliases\tshape\tgrade\tN\tvalid for\tcitation\n";
    for c in BULK {
        out += &format!(
            "{}\t{}\t{}\t{:?}\t{}\t{}\t{}\n",
            c.name,
            aliases_of(c.name).join(","),
            c.shape.name(),
            c.grade,
            c.n_definition.formula(),
            c.n_range.describe("N"),
            c.citation
        );
    }
    out += "\nGrade A: two independent sources or an exact limit; B: one source or a strong internal check;\n\
            C: recalled, unverified (plotted dashed, never gated). Names are case-insensitive, `_` = `-`.\n";
    out
}
