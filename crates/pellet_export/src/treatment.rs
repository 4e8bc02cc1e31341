//! Contact treatments for meshing: where two pellets (or a pellet and the
//! wall) touch, the fluid between them thins to nothing and a volume
//! mesher makes cells of zero volume. The standard remedies (Dixon et al.,
//! *AIChE J.* 59 (2013) 3542; Eppinger et al., *Chem. Eng. J.* 166 (2011) 324):
//!
//! - **global shrink**: every pellet is scaled about its centroid by a
//!   factor below 1 (e.g. 0.99), opening every contact;
//! - **bridges**: a small cylinder of a given diameter joins two surfaces
//!   closer than a gap, along the line between their nearest points, so
//!   the contact becomes a solid neck the mesher can resolve;
//! - **caps**: both pellets are cut flat near the contact (the part beyond
//!   a plane is taken away by a mesh boolean, [`crate::unite::cut`]) so
//!   that a gap of a given width remains between two flat faces; where the
//!   plane does not separate the two (a pellet in the mouth of a ring's
//!   bore), only inside a ball around the contact.
//!
//! The same applies to pellet–wall and pellet–floor contacts (a bridge then
//! runs into the wall or floor; a cap cuts the pellet parallel to the
//! wall's tangent plane or the floor).
//! Shrink can be combined with either bridges or caps (it is applied first);
//! bridges and caps exclude each other. Each treatment reports how many
//! contacts it treated and the porosity change it causes, −ΔV_solid over
//! the tube volume of the exported range (see [`TreatmentReport`]).

use std::collections::HashMap;

use pellet_analysis::clip::volume_in_slab;
use pellet_analysis::{Geometry, LineCaster};
use pellet_geom::math::{Point, Real, Vector};
use pellet_geom::{Bed, ClosedForm, Pellet, PlacedPellet, TriMesh};

use crate::contacts::{find_contacts, Contact, Partner};
use crate::scene::{enclosed_volume, world_mesh};
use crate::unite::Cap;
use crate::ExportError;

/// Which treatments to apply (lengths in m).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Treatment {
    /// Scale factor of every pellet about its centroid, in [0.5, 1].
    pub shrink: Option<Real>,
    /// Bridges: (gap below which surfaces are joined, bridge diameter).
    pub bridges: Option<(Real, Real)>,
    /// Caps: the gap left between surfaces closer than it, cut flat.
    pub caps: Option<Real>,
}

/// A bridge: a closed cylinder joining two surfaces.
#[derive(Clone, Debug, PartialEq)]
pub struct Bridge {
    /// The contact it treats.
    pub contact: Contact,
    /// Its surface (world, m), 16 sides.
    pub mesh: TriMesh,
    /// Its volume outside the pellets and inside the tube and the range (m³).
    pub added_volume: Real,
}

/// One treatment's effect.
#[derive(Clone, Debug, PartialEq)]
pub struct TreatmentLine {
    /// `shrink`, `bridges` or `caps`.
    pub name: &'static str,
    /// Pellet–pellet contacts treated.
    pub pellet_contacts: usize,
    /// Pellet–wall contacts treated.
    pub wall_contacts: usize,
    /// Pellet–floor contacts treated.
    pub floor_contacts: usize,
    /// Change of the porosity of the exported range, −ΔV_solid / V_range.
    pub porosity_change: Real,
    /// The parameters, for the report.
    pub parameters: String,
}

/// What the treatments did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreatmentReport {
    /// One line per treatment applied, in order.
    pub lines: Vec<TreatmentLine>,
    /// The tube volume of the exported range, πR²(z1 − z0) (m³).
    pub range_volume: Real,
}

/// The treated geometry.
pub struct Treated {
    /// The world mesh of each exported pellet, in the order of `indices`.
    pub meshes: Vec<TriMesh>,
    /// The bridges, if any.
    pub bridges: Vec<Bridge>,
    /// The contacts treated: those the bridges or caps treat, else those a shrink opens (found
    /// below `detect_gap` on the untreated bed); empty for no treatment.
    pub contacts: Vec<Contact>,
    /// What was done.
    pub report: TreatmentReport,
}

/// The pellet scaled by `factor` about its centroid (mesh, closed form,
/// bounding radius, volume).
pub fn scaled_pellet(pellet: &Pellet, factor: Real) -> Pellet {
    let mut p = pellet.clone();
    p.mesh.scale(factor);
    p.bounding_radius *= factor;
    p.properties.volume *= factor.powi(3);
    p.closed_form = p.closed_form.map(|c| match c {
        ClosedForm::Sphere { radius } => ClosedForm::Sphere { radius: radius * factor },
        ClosedForm::Cylinder { radius, half_height } => {
            ClosedForm::Cylinder { radius: radius * factor, half_height: half_height * factor }
        }
        ClosedForm::HollowCylinder { inner_radius, outer_radius, half_height } => ClosedForm::HollowCylinder {
            inner_radius: inner_radius * factor,
            outer_radius: outer_radius * factor,
            half_height: half_height * factor,
        },
    });
    p
}

/// (pellet–pellet, pellet–wall, pellet–floor) contacts.
fn count(contacts: &[Contact]) -> (usize, usize, usize) {
    let of = |p: Partner| contacts.iter().filter(|c| c.partner == p).count();
    let (wall, floor) = (of(Partner::Wall), of(Partner::Floor));
    (contacts.len() - wall - floor, wall, floor)
}

/// Applies `treatment` to the pellets `indices` of `bed`, exported over
/// the axial `range` (m). `detect_gap` (m) is the gap below which a
/// contact counts as one that a shrink opens (for its report).
pub fn apply(
    bed: &Bed,
    indices: &[usize],
    range: (Real, Real),
    treatment: &Treatment,
    detect_gap: Real,
) -> Result<Treated, ExportError> {
    let radius = 0.5 * bed.tube.diameter;
    let range_volume = std::f64::consts::PI * radius * radius * (range.1 - range.0);
    let mut report = TreatmentReport { lines: Vec::new(), range_volume };
    if treatment.bridges.is_some() && treatment.caps.is_some() {
        return Err(ExportError::BadParameter(
            "bridges and caps exclude each other; choose one (either can be combined with --shrink)".into(),
        ));
    }
    let mut treated_bed = bed.clone();
    let mut treated_contacts = Vec::new();
    if let Some(f) = treatment.shrink {
        if !(0.5..=1.0).contains(&f) {
            return Err(ExportError::BadParameter(format!(
                "--shrink must be 0.5 to 1 (got {}); 0.99 is usual",
                pellet_geom::math::shown(f)
            )));
        }
        treated_bed.pellet_types = bed.pellet_types.iter().map(|p| scaled_pellet(p, f)).collect();
        let slab = |b: &Bed, i: usize| {
            let pose = &b.pellets[i];
            volume_in_slab(&b.pellet_types[pose.type_index as usize], pose, range.0, range.1, Geometry::Mesh)
        };
        let removed: Real = indices.iter().map(|&i| slab(bed, i) - slab(&treated_bed, i)).sum();
        let opened = find_contacts(bed, indices, detect_gap);
        let (pellet_contacts, wall_contacts, floor_contacts) = count(&opened);
        report.lines.push(TreatmentLine {
            name: "shrink",
            pellet_contacts,
            wall_contacts,
            floor_contacts,
            porosity_change: removed / range_volume,
            parameters: format!("factor {f}; contacts counted below a gap of {:.4} mm", detect_gap * 1e3),
        });
        treated_contacts = opened;
    }
    let mut meshes: Vec<TriMesh> = indices
        .iter()
        .map(|&i| {
            let pose = &bed.pellets[i];
            world_mesh(&bed.pellet_types[pose.type_index as usize], pose, treatment.shrink.unwrap_or(1.0))
        })
        .collect();
    let mut bridges = Vec::new();
    if let Some((gap, diameter)) = treatment.bridges {
        positive("the bridge gap", gap)?;
        positive("the bridge diameter", diameter)?;
        let contacts = find_contacts(&treated_bed, indices, gap);
        for c in &contacts {
            let mesh = bridge_mesh(c, 0.5 * diameter, 16);
            let added_volume = bridge_volume_outside(&treated_bed, c, 0.5 * diameter, range);
            bridges.push(Bridge { contact: *c, mesh, added_volume });
        }
        let (pellet_contacts, wall_contacts, floor_contacts) = count(&contacts);
        let added: Real = bridges.iter().map(|b| b.added_volume).sum();
        report.lines.push(TreatmentLine {
            name: "bridges",
            pellet_contacts,
            wall_contacts,
            floor_contacts,
            porosity_change: -added / range_volume,
            parameters: format!(
                "surfaces closer than {:.4} mm joined by cylinders of {:.4} mm",
                gap * 1e3,
                diameter * 1e3
            ),
        });
        treated_contacts = contacts;
    }
    if let Some(gap) = treatment.caps {
        positive("the cap gap", gap)?;
        let contacts = find_contacts(&treated_bed, indices, gap);
        let slot: HashMap<usize, usize> = indices.iter().enumerate().map(|(k, &i)| (i, k)).collect();
        let before: Real = meshes.iter().map(enclosed_volume).sum();
        // Each surface keeps to its side of a plane, `gap` apart in all. A plane that does not
        // separate the two pellets (one lies in the mouth of the other's bore, so each reaches
        // millimetres past it away from the contact) cuts only near the contact: inside a ball
        // in which two spheres of the larger bounding radius R come within 2 gaps of each other
        // (radius √(2 R gap)); everywhere, it would take away whole rims.
        let reach =
            |k: usize, n: &Vector| meshes[k].vertices.iter().map(|v| n.dot(&v.coords)).fold(Real::MIN, Real::max);
        let bounding = |i: usize| treated_bed.pellet_types[treated_bed.pellets[i].type_index as usize].bounding_radius;
        let mut planes: Vec<Vec<Cap>> = vec![Vec::new(); meshes.len()];
        for c in &contacts {
            let mid = c.midpoint();
            let (offset_own, offset_partner) = match c.partner {
                Partner::Pellet(_) => (c.normal.dot(&mid.coords) - 0.5 * gap, -c.normal.dot(&mid.coords) - 0.5 * gap),
                Partner::Wall | Partner::Floor => (c.normal.dot(&c.partner_point.coords) - gap, 0.0),
            };
            let mut within = None;
            if let Partner::Pellet(j) = c.partner {
                // How far each reaches past its contact point along the normal.
                let own = reach(slot[&c.pellet], &c.normal) - c.normal.dot(&c.point.coords);
                let partner = reach(slot[&j], &-c.normal) + c.normal.dot(&c.partner_point.coords);
                if own.max(partner) > 0.5 * gap {
                    within = Some((mid, (2.0 * bounding(c.pellet).max(bounding(j)) * gap).sqrt()));
                }
                planes[slot[&j]].push(Cap { normal: -c.normal, offset: offset_partner, within });
            }
            planes[slot[&c.pellet]].push(Cap { normal: c.normal, offset: offset_own, within });
        }
        for (k, (mesh, planes)) in meshes.iter_mut().zip(&planes).enumerate() {
            if !planes.is_empty() {
                *mesh = crate::unite::cut(mesh, planes)
                    .map_err(|why| ExportError::Union(format!("pellet {}: {why}", indices[k])))?;
            }
        }
        let after: Real = meshes.iter().map(enclosed_volume).sum();
        let (pellet_contacts, wall_contacts, floor_contacts) = count(&contacts);
        report.lines.push(TreatmentLine {
            name: "caps",
            pellet_contacts,
            wall_contacts,
            floor_contacts,
            porosity_change: (before - after) / range_volume,
            parameters: format!("surfaces closer than {:.4} mm cut flat to leave {:.4} mm", gap * 1e3, gap * 1e3),
        });
        treated_contacts = contacts;
    }
    Ok(Treated { meshes, bridges, contacts: treated_contacts, report })
}

fn positive(what: &str, value: Real) -> Result<(), ExportError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ExportError::BadParameter(format!("{what} must be > 0 (got {} mm)", pellet_geom::math::shown(value * 1e3))))
    }
}

/// Half the length of a bridge: half the gap plus the depth it reaches
/// into each surface (its radius: enough to bury its ends in any surface
/// whose radius of curvature exceeds the bridge's radius).
fn bridge_half_length(contact: &Contact, radius: Real) -> Real {
    0.5 * contact.gap.abs() + radius
}

/// A closed cylinder of `radius` along the contact normal, centred between the surfaces.
pub fn bridge_mesh(contact: &Contact, radius: Real, segments: usize) -> TriMesh {
    let axis = contact.normal;
    let (u, v) = perpendicular_basis(&axis);
    let half = bridge_half_length(contact, radius);
    let centre = contact.midpoint();
    let n = segments.max(3);
    let mut vertices = Vec::with_capacity(2 * n + 2);
    for s in [-half, half] {
        for k in 0..n {
            let a = k as Real * std::f64::consts::TAU / n as Real;
            vertices.push(centre + axis * s + (u * a.cos() + v * a.sin()) * radius);
        }
    }
    vertices.push(centre - axis * half);
    vertices.push(centre + axis * half);
    let (bottom, top, n32) = (2 * n as u32, 2 * n as u32 + 1, n as u32);
    let mut triangles = Vec::with_capacity(4 * n);
    for k in 0..n32 {
        let next = (k + 1) % n32;
        triangles.push([k, next, next + n32]);
        triangles.push([k, next + n32, k + n32]);
        triangles.push([bottom, next, k]);
        triangles.push([top, k + n32, next + n32]);
    }
    TriMesh { vertices, triangles }
}

fn perpendicular_basis(axis: &Vector) -> (Vector, Vector) {
    let helper = if axis.x.abs() < 0.9 { Vector::x() } else { Vector::y() };
    let u = axis.cross(&helper).normalize();
    (u, axis.cross(&u))
}

/// Point-in-pellet queries for one placed pellet: its closed form where it
/// has one, else the crossings of a vertical line with its mesh (the
/// raster `voidprof` uses; far faster than the mesh's winding number).
struct Solid<'a> {
    pose: &'a PlacedPellet,
    shape: Option<ClosedForm>,
    caster: Option<LineCaster>,
}

impl<'a> Solid<'a> {
    fn new(bed: &'a Bed, i: usize) -> Solid<'a> {
        let pose = &bed.pellets[i];
        let pellet = &bed.pellet_types[pose.type_index as usize];
        let caster = pellet.closed_form.is_none().then(|| LineCaster::new(pellet, pose, Geometry::Mesh));
        Solid { pose, shape: pellet.closed_form, caster }
    }

    fn contains(&self, p: &Point) -> bool {
        match (&self.shape, &self.caster) {
            (Some(shape), _) => shape.signed_distance(&self.pose.to_body(p)) < 0.0,
            (None, Some(caster)) => {
                let mut chords = Vec::new();
                caster.intervals(p.x, p.y, &mut chords);
                chords.iter().any(|&(lo, hi)| lo <= p.z && p.z < hi)
            }
            (None, None) => false,
        }
    }
}

/// The bridge's volume that adds solid: outside both pellets, inside the
/// tube and within the axial range. Lines parallel to the axis through 6
/// equal-area rings × 16 angles (midpoint rule over the section); along
/// each line, 48 samples with every change of state located by bisection,
/// so the length is exact unless a line crosses a surface twice within
/// one step (1/48 of the bridge).
fn bridge_volume_outside(bed: &Bed, contact: &Contact, radius: Real, range: (Real, Real)) -> Real {
    let (rings, angles, steps) = (6, 16, 48);
    let axis = contact.normal;
    let (u, v) = perpendicular_basis(&axis);
    let half = bridge_half_length(contact, radius);
    let centre = contact.midpoint();
    let tube = 0.5 * bed.tube.diameter;
    let step = 2.0 * half / steps as Real;
    let own = Solid::new(bed, contact.pellet);
    let partner = match contact.partner {
        Partner::Pellet(j) => Some(Solid::new(bed, j)),
        Partner::Wall | Partner::Floor => None,
    };
    let mut length = 0.0;
    for ring in 0..rings {
        let r = radius * ((ring as Real + 0.5) / rings as Real).sqrt();
        for k in 0..angles {
            let a = (k as Real + 0.5) * std::f64::consts::TAU / angles as Real;
            let offset = (u * a.cos() + v * a.sin()) * r;
            let adds = |s: Real| {
                let p = centre + axis * s + offset;
                let in_tube = p.x.hypot(p.y) < tube && (range.0..range.1).contains(&p.z);
                in_tube && !own.contains(&p) && !partner.as_ref().is_some_and(|q| q.contains(&p))
            };
            let (mut s0, mut before) = (-half, adds(-half));
            for n in 1..=steps {
                let s1 = -half + n as Real * step;
                let now = adds(s1);
                if now == before {
                    if now {
                        length += step;
                    }
                } else {
                    let (mut lo, mut hi) = (s0, s1);
                    for _ in 0..40 {
                        let mid = 0.5 * (lo + hi);
                        if adds(mid) == before {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    let crossing = 0.5 * (lo + hi);
                    length += if before { crossing - s0 } else { s1 - crossing };
                }
                (s0, before) = (s1, now);
            }
        }
    }
    // Each line stands for an equal share of the section's area.
    std::f64::consts::PI * radius * radius * length / (rings * angles) as Real
}

#[cfg(test)]
mod tests;
