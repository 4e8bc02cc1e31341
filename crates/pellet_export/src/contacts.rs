//! Contacts to treat before meshing: pairs of surfaces closer than a gap.
//!
//! # How the gap is measured
//!
//! The gap is the distance between the two surfaces along the line that
//! joins their nearest points (negative when they overlap):
//!
//! - **sphere–sphere**: exact, `|c₁ − c₂| − r₁ − r₂` (closed forms);
//! - **sphere–wall**: exact, `R − ρ − r` (ρ the centre's distance from the axis);
//! - **other pairs with closed forms** (cylinders, rings, and either with a
//!   sphere): parry's contact query on the exact solids (GJK, EPA where they
//!   overlap), a ring as 128 convex wedges about its axis whose chords cut
//!   into its bore by at most 3·10⁻⁴ of the bore's radius
//!   ([`pellet_geom::parry_boundary::closed_form_contact`]); the normal
//!   separates the two solids, so a cap cut along it keeps each pellet;
//! - **pairs without closed forms** (lobed, multi-hole, user meshes): the
//!   smallest distance between the two meshes' vertices, which overestimates
//!   the true gap by at most one edge length; the contact's normal is the
//!   mean of the two surfaces' vertex normals and its points each mesh's
//!   extreme vertex along it (refined twice), which places bridges and caps
//!   within about an edge of the true contact;
//! - **other pellets against the wall**: `R − max ρ` over the mesh's
//!   vertices, exact for the mesh (the distance from the axis is convex, so
//!   its maximum over a polyhedron is at a vertex);
//! - **against the floor** (z = 0): the pellet's lowest point, exact for
//!   closed forms, the lowest mesh vertex otherwise (exact for the mesh).
//!
//! Each contact carries the nearest points and the unit normal from the
//! first pellet towards its partner, which place bridges and caps.

use pellet_geom::math::{Point, Real, Vector};
use pellet_geom::parry_boundary::{closed_form_contact, PlacedClosedForm};
use pellet_geom::{Bed, ClosedForm, Pellet, PlacedPellet};

use crate::scene::radial_direction;

/// What a pellet touches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Partner {
    /// Another pellet (index into the bed's pellets).
    Pellet(usize),
    /// The tube wall.
    Wall,
    /// The floor, z = 0.
    Floor,
}

/// A pair of surfaces closer than the threshold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// The first pellet (index into the bed's pellets).
    pub pellet: usize,
    /// What it touches.
    pub partner: Partner,
    /// Surface gap (m), negative for an overlap.
    pub gap: Real,
    /// Nearest point on the first pellet's surface (world, m).
    pub point: Point,
    /// Nearest point on the partner's surface (world, m).
    pub partner_point: Point,
    /// Unit normal from the first pellet towards the partner.
    pub normal: Vector,
}

impl Contact {
    /// The point halfway between the two surfaces.
    pub fn midpoint(&self) -> Point {
        Point::from((self.point.coords + self.partner_point.coords) * 0.5)
    }
}

/// Every pellet–pellet and pellet–wall contact among the pellets `indices`
/// of `bed` whose gap is below `gap` (m), pellet pairs first, sorted by
/// index. Bounding spheres cull the pairs (sorted along z).
pub fn find_contacts(bed: &Bed, indices: &[usize], gap: Real) -> Vec<Contact> {
    let reach = |i: usize| bed.pellet_types[bed.pellets[i].type_index as usize].bounding_radius;
    let mut order = indices.to_vec();
    order.sort_by(|&a, &b| bed.pellets[a].position[2].total_cmp(&bed.pellets[b].position[2]));
    let max_reach = indices.iter().map(|&i| reach(i)).fold(0.0, Real::max);
    let mut found = Vec::new();
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            let (pi, pj) = (&bed.pellets[i], &bed.pellets[j]);
            if pj.position[2] - pi.position[2] > 2.0 * max_reach + gap {
                break;
            }
            if (pi.centre() - pj.centre()).norm() > reach(i) + reach(j) + gap {
                continue;
            }
            let (a, b) = (i.min(j), i.max(j));
            if let Some(c) = pair(bed, a, b, gap).filter(|c| c.gap < gap) {
                found.push(c);
            }
        }
    }
    found.sort_by_key(|c| (c.pellet, partner_index(c)));
    let radius = 0.5 * bed.tube.diameter;
    let mut walls: Vec<Contact> =
        indices.iter().filter_map(|&i| wall(bed, i, radius)).filter(|c| c.gap < gap).collect();
    walls.sort_by_key(|c| c.pellet);
    found.extend(walls);
    let mut floors: Vec<Contact> = indices.iter().map(|&i| floor(bed, i)).filter(|c| c.gap < gap).collect();
    floors.sort_by_key(|c| c.pellet);
    found.extend(floors);
    found
}

/// The gap between pellet `i` and the floor z = 0.
fn floor(bed: &Bed, i: usize) -> Contact {
    let pose = &bed.pellets[i];
    let pellet = type_of(bed, pose);
    let lowest = pellet.mesh.vertices.iter().map(|v| pose.to_world(v)).min_by(|a, b| a.z.total_cmp(&b.z));
    let mut point = lowest.unwrap_or_else(|| pose.centre());
    if pellet.closed_form.is_some() {
        point.z = pose.position[2] - pellet_analysis::half_extent_z(pellet, pose);
        if let Some(ClosedForm::Sphere { .. }) = pellet.closed_form {
            (point.x, point.y) = (pose.position[0], pose.position[1]);
        }
    }
    let partner_point = Point::new(point.x, point.y, 0.0);
    Contact { pellet: i, partner: Partner::Floor, gap: point.z, point, partner_point, normal: -Vector::z() }
}

fn partner_index(c: &Contact) -> usize {
    match c.partner {
        Partner::Pellet(j) => j,
        Partner::Wall | Partner::Floor => usize::MAX,
    }
}

fn type_of<'a>(bed: &'a Bed, pose: &PlacedPellet) -> &'a Pellet {
    &bed.pellet_types[pose.type_index as usize]
}

/// The nearest points of pellets `a` and `b` and their gap; `None` for closed forms farther
/// apart than `max_gap`.
fn pair(bed: &Bed, a: usize, b: usize, max_gap: Real) -> Option<Contact> {
    let (pa, pb) = (&bed.pellets[a], &bed.pellets[b]);
    let (ta, tb) = (type_of(bed, pa), type_of(bed, pb));
    let along_centres = || {
        let d = pb.centre() - pa.centre();
        if d.norm() > 0.0 {
            d.normalize()
        } else {
            Vector::z()
        }
    };
    let contact = |gap: Real, point: Point, partner_point: Point, normal: Vector| Contact {
        pellet: a,
        partner: Partner::Pellet(b),
        gap,
        point,
        partner_point,
        normal,
    };
    match (ta.closed_form, tb.closed_form) {
        (Some(ClosedForm::Sphere { radius: ra }), Some(ClosedForm::Sphere { radius: rb })) => {
            let n = along_centres();
            let gap = (pb.centre() - pa.centre()).norm() - ra - rb;
            Some(contact(gap, pa.centre() + n * ra, pb.centre() - n * rb, n))
        }
        (Some(ca), Some(cb)) => {
            // The exact contact of the two solids (a ring as wedges about its axis), whose normal
            // separates them: a rim against a curved side has its normal between the rim's two
            // faces, where either surface's normal would let the rim's pellet reach millimetres
            // past the contact and a cap cut along it take most of that pellet.
            let placed =
                |p: &PlacedPellet, shape| PlacedClosedForm { shape, centre: p.centre(), rotation: p.rotation() };
            let (gap, point, partner_point, normal) = closed_form_contact(&placed(pa, ca), &placed(pb, cb), max_gap)?;
            Some(contact(gap, point, partner_point, normal))
        }
        _ => {
            let verts_a = world_vertices_near(ta, pa, pb.centre(), tb.bounding_radius);
            let verts_b = world_vertices_near(tb, pb, pa.centre(), ta.bounding_radius);
            let mut best: Option<(Real, usize, usize)> = None;
            for (ia, va) in &verts_a {
                for (ib, vb) in &verts_b {
                    let d = (vb - va).norm();
                    if best.is_none_or(|(bd, _, _)| d < bd) {
                        best = Some((d, *ia, *ib));
                    }
                }
            }
            let (d, mut ia, mut ib) = best?;
            // The nearest vertices can sit well to the side of the contact
            // (about an edge): the normal is the mean of the two surfaces'
            // vertex normals, and the points are refined to each mesh's
            // extreme vertex along it (the contact point of smooth convex
            // surfaces), twice.
            let normal_at = |ia: usize, ib: usize| {
                let n = pa.rotation() * vertex_normal(&ta.mesh, ia) - pb.rotation() * vertex_normal(&tb.mesh, ib);
                if n.norm() > 0.0 {
                    n.normalize()
                } else {
                    along_centres()
                }
            };
            let mut n = normal_at(ia, ib);
            for _ in 0..2 {
                let extreme = |verts: &[(usize, Point)], sign: Real| {
                    verts
                        .iter()
                        .max_by(|x, y| (sign * n.dot(&x.1.coords)).total_cmp(&(sign * n.dot(&y.1.coords))))
                        .map(|v| v.0)
                };
                (ia, ib) = (extreme(&verts_a, 1.0)?, extreme(&verts_b, -1.0)?);
                n = normal_at(ia, ib);
            }
            let (va, vb) = (pa.to_world(&ta.mesh.vertices[ia]), pb.to_world(&tb.mesh.vertices[ib]));
            Some(contact(d, va, vb, n))
        }
    }
}

/// The area-weighted mean normal of the triangles around vertex `v` (unit).
fn vertex_normal(mesh: &pellet_geom::TriMesh, v: usize) -> Vector {
    let sum: Vector =
        (0..mesh.face_count()).filter(|&t| mesh.triangles[t].contains(&(v as u32))).map(|t| mesh.area_normal(t)).sum();
    if sum.norm() > 0.0 {
        sum.normalize()
    } else {
        sum
    }
}

/// (index, world position) of the vertices of `pellet` at `pose` within
/// `reach` (plus a margin) of `centre`.
fn world_vertices_near(pellet: &Pellet, pose: &PlacedPellet, centre: Point, reach: Real) -> Vec<(usize, Point)> {
    let limit = reach * 1.05;
    pellet
        .mesh
        .vertices
        .iter()
        .enumerate()
        .map(|(i, v)| (i, pose.to_world(v)))
        .filter(|(_, w)| (w - centre).norm() <= limit)
        .collect()
}

/// The gap between pellet `i` and the wall of radius `radius`.
fn wall(bed: &Bed, i: usize, radius: Real) -> Option<Contact> {
    let pose = &bed.pellets[i];
    let pellet = type_of(bed, pose);
    let (point, rho) = match pellet.closed_form {
        Some(ClosedForm::Sphere { radius: r }) => {
            let c = pose.centre();
            (c + radial_direction(&c) * r, c.x.hypot(c.y) + r)
        }
        _ => pellet
            .mesh
            .vertices
            .iter()
            .map(|v| {
                let w = pose.to_world(v);
                (w, w.x.hypot(w.y))
            })
            .max_by(|x, y| x.1.total_cmp(&y.1))?,
    };
    let normal = radial_direction(&point);
    let partner_point = Point::new(normal.x * radius, normal.y * radius, point.z);
    Some(Contact { pellet: i, partner: Partner::Wall, gap: radius - rho, point, partner_point, normal })
}

#[cfg(test)]
mod tests {
    use super::*;
    use pellet_geom::{Resolution, ShapeSpec, Tube};

    fn bed(pellet: Pellet, centres_mm: &[[Real; 3]], tube_mm: Real) -> Bed {
        Bed {
            tube: Tube { diameter: tube_mm * 1e-3, lid_height: None },
            pellet_types: vec![pellet],
            pellets: centres_mm
                .iter()
                .map(|c| PlacedPellet {
                    type_index: 0,
                    position: c.map(|x| x * 1e-3),
                    orientation: [1.0, 0.0, 0.0, 0.0],
                })
                .collect(),
        }
    }

    /// Two pellets of `spec` at `poses` (centre in mm, orientation w, x, y, z) in a 30 mm tube:
    /// their contact's gap (m), and how far (m) each reaches past the plane through its
    /// midpoint along its normal (the plane a cap cuts along), counting only the vertices
    /// within `near` (m) of the midpoint when given.
    fn past_the_contact_plane(
        spec: ShapeSpec,
        poses: [([Real; 3], [Real; 4]); 2],
        near: Option<Real>,
    ) -> (Real, Real, Real) {
        let pellet = Pellet::build(spec, Resolution::default()).unwrap();
        let b = Bed {
            tube: Tube { diameter: 0.03, lid_height: None },
            pellet_types: vec![pellet],
            pellets: poses
                .iter()
                .map(|&(mm, orientation)| PlacedPellet { type_index: 0, position: mm.map(|x| x * 1e-3), orientation })
                .collect(),
        };
        let contacts = find_contacts(&b, &[0, 1], 1e-4);
        let c = contacts.iter().find(|c| c.partner == Partner::Pellet(1)).expect("the pair touches");
        let mid = c.midpoint();
        let reach = |k: usize, n: Vector| {
            let p = &b.pellets[k];
            b.pellet_types[0]
                .mesh
                .vertices
                .iter()
                .map(|v| p.to_world(v) - mid)
                .filter(|d| near.is_none_or(|r| d.norm() <= r))
                .map(|d| n.dot(&d))
                .fold(Real::MIN, Real::max)
        };
        (c.gap, reach(0, c.normal), reach(1, -c.normal))
    }

    const RING: ShapeSpec = ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 };

    /// Two cylinders of a settled 20-cylinder bed (D = 30 mm), the second's curved side
    /// touching the first's cap at its rim. The second's normal at the first's nearest vertex
    /// does not separate them (the first reaches 7.8 mm past that plane, and a cap cut along
    /// it took 511 mm³ of that pellet). The exact contact of the two cylinders leaves 0.001 mm
    /// of each.
    #[test]
    fn a_contact_normal_separates_the_two_pellets() {
        let (gap, r0, r1) = past_the_contact_plane(
            ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 },
            [
                (
                    [3.064513634749823, -8.99017616883717, 12.46548783134918],
                    [0.0887205835562855, 0.7820182294397346, 0.4952860113978071, 0.3677878652036065],
                ),
                (
                    [-4.75981573836584, -6.9384165808269325, 22.022278665450578],
                    [-0.740356053784457, 0.3519951077142928, 0.3582724913332724, -0.4467809079669362],
                ),
            ],
            None,
        );
        assert!(gap.abs() < 1e-4, "gap {gap}");
        assert!(r0 < 0.02e-3 && r1 < 0.02e-3, "past the contact plane: {:.3} mm and {:.3} mm", r0 * 1e3, r1 * 1e3);
    }

    /// Two rings of a settled 20-ring bed (D = 30 mm; pellets 1 and 5), touching outside their
    /// bores: the exact contact of the two rings leaves 0.005 mm of either past its plane.
    #[test]
    fn two_rings_touching_outside_their_bores_are_separated_by_their_contact_plane() {
        let (gap, r0, r1) = past_the_contact_plane(
            RING,
            [
                (
                    [0.851055905, -3.809004037, 7.055640915],
                    [-0.767974724188, -0.398691146339, -0.106386112277, 0.48983894083],
                ),
                (
                    [0.562717816, -8.236337742, 17.309300781],
                    [-0.312533324842, 0.369631546352, 0.131992623681, 0.865027969547],
                ),
            ],
            None,
        );
        assert!(gap.abs() < 0.01e-3, "gap {gap}");
        assert!(r0 < 0.01e-3 && r1 < 0.01e-3, "past the contact plane: {:.4} mm and {:.4} mm", r0 * 1e3, r1 * 1e3);
    }

    /// Two rings of the same bed (pellets 12 and 17), the first's curved side in the mouth of
    /// the second's bore, touching its inner rim: no plane separates them (the second's far rim
    /// reaches 1.9 mm past the contact plane, which is why caps there cut only near the
    /// contact), but the exact contact's plane is tangent to both: within 0.3 mm of the contact
    /// neither reaches 0.01 mm past it (the inner rim rises past it away from the contact, by
    /// 0.035 mm at 1.2 mm).
    #[test]
    fn a_ring_in_the_mouth_of_another_has_its_exact_contact() {
        let poses = [
            (
                [7.389757881349915, 5.409834332404802, 34.78638908750541],
                [-0.015062854907094744, 0.38706294441201294, -0.5056823636805197, -0.7708701152124354],
            ),
            (
                [6.275251623077952, -6.054976475403134, 38.24099341264039],
                [-0.38783801070933466, 0.2105800834784721, -0.8212382958644834, -0.3616702466291985],
            ),
        ];
        let (gap, r0, r1) = past_the_contact_plane(RING, poses, Some(0.3e-3));
        assert!(gap.abs() < 0.01e-3, "gap {gap}");
        assert!(r0 < 0.01e-3 && r1 < 0.01e-3, "near the contact: {:.4} mm and {:.4} mm", r0 * 1e3, r1 * 1e3);
        let (_, _, far) = past_the_contact_plane(RING, poses, None);
        assert!(far > 1e-3, "the far rim: {:.3} mm", far * 1e3);
    }

    #[test]
    fn cylinder_faces_and_walls_are_found_with_their_gaps() {
        let cyl =
            Pellet::build(ShapeSpec::Cylinder { diameter_mm: 10.0, height_mm: 10.0 }, Resolution::default()).unwrap();
        // Stacked face to face 0.05 mm apart; a third 2 mm above; the first 0.1 mm from the wall.
        let b = bed(cyl, &[[4.9, 0.0, 5.0], [4.9, 0.0, 15.05], [4.9, 0.0, 27.05]], 20.0);
        let all: Vec<usize> = (0..3).collect();
        let contacts = find_contacts(&b, &all, 0.2e-3);
        let pairs: Vec<_> = contacts.iter().map(|c| (c.pellet, c.partner)).collect();
        assert_eq!(
            pairs,
            [(0, Partner::Pellet(1)), (0, Partner::Wall), (1, Partner::Wall), (2, Partner::Wall), (0, Partner::Floor)],
            "{contacts:?}"
        );
        assert!((contacts[0].gap - 0.05e-3).abs() < 1e-9, "{}", contacts[0].gap);
        assert!((contacts[0].normal - Vector::z()).norm() < 1e-4, "{:?}", contacts[0].normal);
        // The rim's vertices may miss the point nearest the wall by the mesh's sagitta.
        assert!(contacts[1].gap >= 0.1e-3 - 1e-12 && contacts[1].gap < 0.11e-3, "{}", contacts[1].gap);
    }

    #[test]
    fn mesh_only_pellets_use_vertex_distances() {
        let mut s = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
        s.closed_form = None;
        let b = bed(s, &[[0.0, 0.0, 6.0], [0.0, 0.0, 16.1]], 40.0);
        let c = find_contacts(&b, &[0, 1], 0.5e-3);
        assert_eq!(c.len(), 1);
        // The poles are vertices of the Fibonacci sphere? Either way: within one edge of 0.1 mm.
        assert!(c[0].gap >= 0.1e-3 - 1e-9 && c[0].gap < 0.6e-3, "{}", c[0].gap);
    }
}
