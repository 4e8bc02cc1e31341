//! Sampled contacts between two non-spherical pellets (`docs/engine.md`, "Contact generation"):
//! each body's surface samples go into the other's signed distance (both ways), clusters are
//! culled by the Lipschitz bound first, rim samples near the other body are refined along the rim
//! angle (rim–rim crossings) and then into the rim's faces (`rim_refine`), and the hits are
//! grouped into patches of one normal reduced to ≤ 4 points. Also: a sphere against any shape
//! (its centre in the shape's SDF, one point).

use super::contact::{Contact, ContactKey, Counterpart, GapKinematics, NormalOwner};
use super::contact_lateral::{lateral_hit, on_outer_side, redundant_hit, LATERAL};
use super::narrow_phase::Pellet;
use super::patch::{patches, reduce, Hit, MERGE, NEAR_BAND, WEDGE_COS};
use super::rim_refine::{deepest_on_line, rim_faces, rim_min, AngleNear};
use super::sample_cache::{PairSamples, SAMPLE_CACHE_MARGIN};
use super::samples::{cone_alignment, Rim};
use super::sdf::{distance, edge_cone, edge_faces, eval, lipschitz};
use crate::math::{axial_distance, Mat3, Real, Vec3};
use crate::shape::ShapeDesc;
use std::f64::consts::TAU;

/// Feature bit: the sample belongs to B (its point went into A's SDF).
const SIDE_B: u32 = 1 << 31;
/// Feature bit: a rim sample refined to the local minimum along its rim.
const REFINED: u32 = 1 << 30;
/// How much deeper (× the other body's bounding radius) the alternative face of an edge may be
/// when the SDF's own face is one that the sample's surface does not allow (`MIN_ALIGN`).
const FACE_SWITCH: Real = 0.02;
/// Distance (× R_b) from an edge of the other body within which a rim sample takes the edge–edge
/// normal (`OneWay::edge_edge`); contacts at rest sit 1e-6–1e-5 m deep, R_b ≈ 7 mm for the
/// paper's pellets, so the band is ~70 µm.
const EDGE_BAND: Real = 1e-2;
/// Edges closer to parallel than this (sine of their angle) are left to the faces.
const EDGE_PARALLEL: Real = 0.1;
/// Distance from an edge (× R_b) below which the SDF's direction is round-off.
const EDGE_EPS: Real = 1e-9;
/// Smallest alignment (cosine of the angle outside the sample's normal cone) of a hit's normal
/// with the sample's own outward normals. A hit at ~90° to the cone is a surface touching
/// edge-on: B's bottom rim lying 1e-9–1e-7 m radially outside A's equal top rim gives A's
/// lateral normal (horizontal) while B's cap faces straight down; those spurious lateral rows
/// at every stacked interface made a stack of 5 cylinders blow up.
/// Round-off made the old `> 0` test pass them (alignment ~1e-7).
const MIN_ALIGN: Real = 0.1;

fn rotation(p: &Pellet<'_>) -> Mat3 {
    *p.body.orientation.to_rotation_matrix().matrix()
}

/// The most a contact gap measured against a pellet of `shape` (bounding radius `r`) can jump
/// under a vanishing motion, beyond its Lipschitz change: where an edge–edge gap takes over from
/// the SDF or gives way to it (both lie within ±`EDGE_BAND` · r of zero there; rings always,
/// cylinders under the velocity-level stepper's rules, `lean`), and 10 µm for a golden-section
/// search (a rim point, the tube's nearest rim point) that lands in another local minimum. A
/// sphere's gaps are closed forms in its centre (a distance between centres, to a plane or an
/// axis, or another shape's SDF at the centre): only round-off, for which 1 nm is ample. Used
/// to skip re-evaluating contacts that stay open (`dynamics::stabilize`).
pub fn gap_jump(shape: &ShapeDesc, r: Real, lean: bool) -> Real {
    let search = 1e-5;
    match shape {
        ShapeDesc::Sphere { .. } => 1e-9,
        ShapeDesc::HollowCylinder { .. } => search + 2.0 * EDGE_BAND * r,
        ShapeDesc::Cylinder { .. } if lean => search + 2.0 * EDGE_BAND * r,
        _ => search,
    }
}

/// The samples of `src` tested against the SDF of `dst`.
struct OneWay<'a> {
    src: Pellet<'a>,
    dst: Pellet<'a>,
    /// src body frame → dst body frame: p ↦ m p + t.
    m: Mat3,
    t: Vec3,
    rs: Mat3,
    rd: Mat3,
    src_is_b: bool,
    /// A rim crossing a convex side gives only its refined point (`sampled_pair`'s `lean`).
    lean: bool,
}

impl<'a> OneWay<'a> {
    fn new(src: Pellet<'a>, dst: Pellet<'a>, src_is_b: bool) -> Self {
        let (rs, rd) = (rotation(&src), rotation(&dst));
        let m = rd.transpose() * rs;
        let t = rd.transpose() * (src.body.position - dst.body.position);
        Self { src, dst, m, t, rs, rd, src_is_b, lean: false }
    }

    /// dst's signed distance at body-frame point `s` of src (no gradient: the callers cull and
    /// search by the value).
    fn phi(&self, s: &Vec3) -> Real {
        distance(self.dst.shape, &(self.m * s + self.t))
    }

    /// The hit of body-frame sample point `s` (sample `i`) of src, or None if src's surface
    /// there faces away from dst's normal (a sample that touches dst only edge-on, e.g. a rim
    /// exactly over an equal rim, where the Euclidean SDF reports the lateral face at depth 0).
    ///
    /// Inside dst near an edge, or within round-off (`EDGE_EPS` · R_b) of an edge outside, the
    /// SDF's face is swapped for the other face of the edge if that one faces src's surface
    /// better and is either as deep up to round-off, or, when src's surface does not allow the
    /// SDF's face at all, at most `FACE_SWITCH` · R_b deeper: for stacked cylinders this gives
    /// the cap normal instead of a radial one from round-off.
    ///
    /// `face`: the outward normal of the face of rim sample `i` that `s` was moved into
    /// (`refined_hit`); that face's normal is then the sample's cone, and the point is the
    /// patch's refined deepest point, neither a fanned face sample nor a rim point.
    fn hit(&self, s: &Vec3, i: usize, feature: u32, face: Option<Vec3>) -> Option<Hit> {
        let pd = self.m * s + self.t;
        let (mut phi, mut g) = eval(self.dst.shape, &pd);
        let face_cone = face.map(|n| (n, n));
        let cone = face_cone.as_ref().unwrap_or(&self.src.geom.cones[i]);
        let cone = (self.m * cone.0, self.m * cone.1);
        let mut align = cone_alignment(&-g, &cone);
        let r_dst = self.dst.geom.bounding_radius;
        for (phi2, g2) in edge_faces(self.dst.shape, &pd, EDGE_EPS * r_dst).into_iter().flatten() {
            let a2 = cone_alignment(&-g2, &cone);
            // A face that src's surface allows keeps the SDF's (shallowest) depth unless the
            // other face is as shallow up to round-off: a rim inside dst near dst's edge has both
            // faces in its cone, and taking the better-aligned, deeper face measured up to
            // FACE_SWITCH · R_b = 1.4e-4 m of penetration that was not there (1.06e-4 m in the
            // pour of `tests/t23_pour_shapes.rs`: true depth 3.7e-6 m).
            let tie = if align > MIN_ALIGN { EDGE_EPS * r_dst } else { FACE_SWITCH * r_dst };
            if phi2 >= phi - tie && a2 > align {
                (phi, g, align) = (phi2, g2, a2);
            }
        }
        if align <= MIN_ALIGN {
            return None;
        }
        if face.is_none() && redundant_hit(self.src.shape, s, &self.src.geom.cones[i], self.dst.shape, &pd, &g) {
            return None;
        }
        // A rim crosses a convex side at points: the refined deepest point of each valley
        // along the rim (`visit`) is the contact, and the rim samples beside it, each with the
        // side's normal where it lies (fanned by 5° over three samples), add only rows that
        // fight it in the velocity stepper's solve. The force-level stepper keeps them: its
        // 20-cylinder bed in `pellet_pack`'s shapes test then rocks past 4 s without them.
        if self.lean
            && self.src.geom.rim_of[i] != u32::MAX
            && feature & REFINED == 0
            && on_outer_side(self.dst.shape, &pd, &g)
        {
            return None;
        }
        // A point inside a face is no edge's: its depth is the SDF's.
        if let Some((n, gap)) = self.edge_edge(s, i, &pd, &cone, feature & REFINED != 0).filter(|_| face.is_none()) {
            (phi, g) = (gap, n);
        }
        let n_out = self.rd * g;
        let p = self.rs * s + self.src.body.position;
        // Cones in terms of n (B → A): dst's outward normal is n if dst is B, −n if dst is A;
        // src's outward normal is the opposite.
        let sign = if self.src_is_b { -1.0 } else { 1.0 };
        let wedge = edge_cone(self.dst.shape, &pd).map(|(e1, e2)| {
            [(self.rd * e1 * sign, self.rd * e2 * sign), (self.rd * cone.0 * -sign, self.rd * cone.1 * -sign)]
        });
        Some(if self.src_is_b {
            let normal = -n_out;
            let feature = feature | SIDE_B;
            Hit { pa: p + normal * phi, pb: p, normal, gap: phi, feature, owner: NormalOwner::A, wedge }
        } else {
            Hit { pa: p, pb: p - n_out * phi, normal: n_out, gap: phi, feature, owner: NormalOwner::B, wedge }
        })
    }

    /// A rim sample of src within `EDGE_BAND` · R_b of an edge of dst (a ring; a cylinder under
    /// the velocity-level stepper's rules, `lean`): the edge–edge
    /// normal (outward from dst, at right angles to both edges) and the gap along it, in dst's
    /// frame. None where the two edges are nearly parallel (stacked rims: the faces decide) or
    /// the normal lies outside either edge's cone of normals. The normal is attached to dst for
    /// the gap's kinematics (`GapKinematics::Point`), which leaves out the part of its rate that
    /// src's rotation makes, as for curved faces; post-stabilisation removes what is left.
    ///
    /// Why: the refined rim point (the deepest along the rim) lies where the two face depths of
    /// dst's edge are equal, and there the Euclidean SDF's choice of the shallower face flips by
    /// 90° with round-off. In the paper's ring bed D = 60.18 mm at rest (241 rings, restarted
    /// from t = 14.3 s) 6141 contact normals flipped by 90° in 400 substeps, most carrying
    /// force, one feature 154 times: the big island stayed unconverged and the kinetic energy
    /// jumped between 1e-15 and 1e-9 J, so wide ring beds never passed the settle test. With the
    /// edge–edge normal: 4 flips, and the bed at rest needs no solver iterations.
    ///
    /// Cylinders flip too, and under the velocity-level stepper a flipped normal is a pump: the
    /// solve holds the rim on one face while it sinks into the other, and projection pushes it
    /// out, every step (`docs/engine.md`, "Edge–edge normals for cylinders"). The force-level
    /// stepper keeps the faces' normals at cylinder edges: its settled cylinder beds flip 270 and
    /// 568 normals in 400 substeps but come to rest anyway, and with the edge–edge normal two of
    /// four creep-prone cylinder beds of the paper study ended with a rocking pellet.
    ///
    /// The gap: at a refined rim point (within O(depth) of where the edges cross) the distance
    /// from the point to the plane through dst's edge normal to n, which is there the distance
    /// between the two edges' tangent lines, the crossing's depth. At any other rim sample that
    /// plane misses the depth by the rims' curvature, (offset along the rim)²/R, either way: the
    /// sample beside a 20 µm crossing of two 10 mm cylinders' rims read 25 µm. There the
    /// gap is how far the point must move along n to leave dst's corner, max(qx/a, qy/b) (n
    /// lies in the corner's cross-section, so this is exact), never deeper than the pellets'
    /// overlap along n, and equal to the plane's distance where the point lies on the corner's
    /// line along n.
    fn edge_edge(&self, s: &Vec3, i: usize, pd: &Vec3, cone: &(Vec3, Vec3), refined: bool) -> Option<(Vec3, Real)> {
        let edged = match self.dst.shape {
            ShapeDesc::HollowCylinder { .. } => true,
            ShapeDesc::Cylinder { .. } => self.lean,
            _ => false,
        };
        if self.src.geom.rim_of[i] == u32::MAX || !edged {
            return None;
        }
        let [(qx, side), (qy, ez)] = edge_faces(self.dst.shape, pd, Real::INFINITY)?;
        if axial_distance(qx, qy) > EDGE_BAND * self.dst.geom.bounding_radius {
            return None;
        }
        let n = self.rim_edge_cross(s, &side)?;
        let len = n.norm();
        let n = if n.dot(&(side + ez)) < 0.0 { -n / len } else { n / len };
        let (a, b) = (n.dot(&side), n.dot(&ez));
        if a < 0.0 || b < 0.0 || cone_alignment(&-n, cone) < WEDGE_COS {
            return None;
        }
        let plane = a * qx + b * qy;
        if refined {
            return Some((n, plane));
        }
        // a² + b² = 1, so the plane's distance is a weighted mean of qx/a and qy/b: the larger
        // is never shallower. A face that n runs along (a or b zero) is never left.
        let exit = [(qx, a), (qy, b)].into_iter().filter(|&(_, c)| c > 0.0).map(|(q, c)| q / c);
        Some((n, exit.fold(plane, Real::max)))
    }

    /// The refined hit of rim sample `i`: at the deepest point along its rim within one sample
    /// spacing, or, when the rim point lies within `max_gap` + `EDGE_BAND` · R_b of dst, at the
    /// deepest point of the lines that leave it at right angles into the rim's two faces, up to
    /// `EDGE_BAND` · R_b away, whichever hit is deeper (the same feature).
    ///
    /// Why the faces: a face lying almost flat against dst overlaps it in a strip (a cap on a
    /// side: 2 √(2 R δ) wide, 0.44 mm at δ = 5 µm), and where the strip is cut off by a rim of
    /// dst next to src's rim its deepest point lies inside src's face, where dst's two faces at
    /// that edge are equally deep, between the face's samples and off src's rim. In the
    /// 620-cylinder bed the rim read 3.4 µm there, the faces 4.8 µm. φ is 1-Lipschitz, so no
    /// point of a line is deeper than the rim by more than its length: farther rims are left out.
    fn refined_hit(&self, i: usize, max_gap: Real) -> Option<Hit> {
        let geo = self.src.geom;
        let rim = &geo.rims[geo.rim_of[i] as usize];
        let step = TAU / rim.count as Real;
        let t0 = step * (i - rim.start) as Real;
        let near = AngleNear::new(t0);
        let f = |t: Real| self.phi(&near.rim_point(rim.radius, rim.z, t));
        let (t, phi) = rim_min(f, t0 - step, t0 + step);
        let s = near.rim_point(rim.radius, rim.z, t);
        let feature = i as u32 | REFINED;
        let mut best = self.hit(&s, i, feature, None);
        // A hit deeper than the signed distance took the edge's deeper face (`hit`), whose depth
        // at an arbitrary point of a flat stretch is not its deepest.
        if phi < 0.0 && best.as_ref().is_some_and(|b| b.gap < phi) {
            if let Some(tk) = self.deeper_face_minimum(rim, &near, &s, t, t0 - step, t0 + step) {
                let h = self.hit(&near.rim_point(rim.radius, rim.z, tk), i, feature, None);
                if let Some(h) = h.filter(|h| best.as_ref().is_none_or(|b| h.gap < b.gap)) {
                    best = Some(h);
                }
            }
        }
        let len = EDGE_BAND * self.dst.geom.bounding_radius;
        if phi > max_gap + len {
            return best;
        }
        for (dir, normal) in rim_faces(rim, t, &near) {
            let Some((u, _)) = deepest_on_line(|u| self.phi(&(s + dir * u)), phi, len) else {
                continue;
            };
            if let Some(h) = self.hit(&(s + dir * u), i, feature, Some(normal)) {
                if best.as_ref().is_none_or(|b| h.gap < b.gap) {
                    best = Some(h);
                }
            }
        }
        best
    }

    /// Where src's rim at angle `t` lies inside dst near an edge of dst parallel to it, the
    /// angle in [lo, hi] at which the deeper of that edge's two faces is deepest along the rim.
    /// The signed distance there is the shallower face's depth, which can be flat along the
    /// rim: upright cylinders side by side with flush caps overlap in a lens all of whose rim
    /// points lie equally far below the other's cap, and the refined point fell anywhere in
    /// it, short of the sides' overlap (7.5 µm seen as 0.3 µm in a 2000-cylinder bed).
    /// Crossing rims are `edge_edge`'s.
    /// `s` is the rim point at `t`, in src's frame.
    fn deeper_face_minimum(&self, rim: &Rim, near: &AngleNear, s: &Vec3, t: Real, lo: Real, hi: Real) -> Option<Real> {
        let at = |t: Real| self.m * near.rim_point(rim.radius, rim.z, t) + self.t;
        let faces = edge_faces(self.dst.shape, &(self.m * s + self.t), EDGE_BAND * self.dst.geom.bounding_radius)?;
        if self.rim_edge_cross(s, &faces[0].1).is_some() {
            return None;
        }
        let k = if faces[0].0 < faces[1].0 { 0 } else { 1 };
        let depth = |t: Real| edge_faces(self.dst.shape, &at(t), Real::INFINITY).map_or(Real::INFINITY, |f| f[k].0);
        Some(rim_min(depth, lo, hi).0).filter(|&tk| tk != t)
    }

    /// t_src × t_dst, the tangents (in dst's frame) of src's rim circle at its body-frame point
    /// `s` and of dst's edge circle whose side faces `side`; None where the two are closer to
    /// parallel than `EDGE_PARALLEL` (stacked or side-by-side rims, where the faces decide).
    fn rim_edge_cross(&self, s: &Vec3, side: &Vec3) -> Option<Vec3> {
        let t_src = self.m * Vec3::new(-s.y, s.x, 0.0);
        let t_dst = Vec3::z().cross(side);
        let n = t_src.cross(&t_dst);
        (n.norm() > EDGE_PARALLEL * t_src.norm() * t_dst.norm()).then_some(n)
    }

    /// The hit for a persistent feature (used to re-evaluate one contact).
    fn feature(&self, feature: u32) -> Option<Hit> {
        let i = (feature & !(SIDE_B | REFINED)) as usize;
        let s = *self.src.geom.samples.get(i)?;
        if feature & REFINED != 0 {
            return self.refined_hit(i, Real::INFINITY);
        }
        self.hit(&s, i, feature & !SIDE_B, None)
    }

    /// Every sample of src that may give a hit at `max_gap` (a rim sample: a refined hit up to
    /// one rim spacing further), visited in cluster order; `visit` is called for each.
    fn each_near(&self, max_gap: Real, mut visit: impl FnMut(usize, Real)) {
        let geo = self.src.geom;
        let lip = lipschitz(self.dst.shape);
        let r_dst = self.dst.geom.bounding_radius;
        let rim_slack = (0..geo.rims.len()).map(|k| geo.rim_spacing(k)).fold(0.0, Real::max);
        let reach = max_gap + rim_slack;
        for cl in &geo.clusters {
            let pc = self.m * cl.centre + self.t;
            // Bounding volume first, then the Lipschitz bound φ(s) ≥ φ(c) − L|s − c|.
            if pc.norm() - cl.radius > r_dst + reach || self.phi(&cl.centre) - lip * cl.radius > reach {
                continue;
            }
            for &i in &cl.members {
                let i = i as usize;
                let phi = self.phi(&geo.samples[i]);
                let rim = geo.rim_of[i];
                let slack = if rim != u32::MAX { geo.rim_spacing(rim as usize) } else { 0.0 };
                if phi <= max_gap + slack {
                    visit(i, phi);
                }
            }
        }
    }

    /// The hits of sample `i` (its SDF value `phi`) at `max_gap`: a rim sample at a local
    /// minimum along its rim gives its refined point, any other sample within `max_gap` itself.
    fn visit(&self, i: usize, phi: Real, max_gap: Real, hits: &mut Vec<Hit>) {
        let geo = self.src.geom;
        let s = &geo.samples[i];
        let rim = geo.rim_of[i];
        if rim != u32::MAX && phi <= max_gap + geo.rim_spacing(rim as usize) {
            let r = &geo.rims[rim as usize];
            let k = i - r.start;
            let prev = r.start + (k + r.count - 1) % r.count;
            let next = r.start + (k + 1) % r.count;
            // Refine only at a local minimum along the rim, so that one crossing gives
            // one refined point (ties broken towards the lower index).
            if phi <= self.phi(&geo.samples[prev]) && phi < self.phi(&geo.samples[next]) {
                hits.extend(self.refined_hit(i, max_gap).filter(|h| h.gap <= max_gap));
                return;
            }
        }
        if phi <= max_gap {
            hits.extend(self.hit(s, i, i as u32, None).filter(|h| h.gap <= max_gap));
        }
    }

    fn collect(&self, max_gap: Real, hits: &mut Vec<Hit>) {
        self.each_near(max_gap, |i, phi| self.visit(i, phi, max_gap, hits));
    }

    /// The samples that may give a hit at any gap limit up to `bound`, in visiting order.
    fn candidates(&self, bound: Real, out: &mut Vec<u32>) {
        out.clear();
        self.each_near(bound, |i, _| out.push(i as u32));
    }

    /// [`Self::collect`] over `candidates` only: the same hits in the same order when every
    /// sample outside them is known to be farther than the limit (`sample_cache`).
    fn collect_from(&self, candidates: &[u32], max_gap: Real, hits: &mut Vec<Hit>) {
        for &i in candidates {
            let i = i as usize;
            let phi = self.phi(&self.src.geom.samples[i]);
            self.visit(i, phi, max_gap, hits);
        }
    }
}

fn contact(a: &Pellet<'_>, b: &Pellet<'_>, h: &Hit, normal: Vec3, owner: NormalOwner) -> Contact {
    Contact {
        a: a.index,
        b: Counterpart::Body(b.index),
        point: 0.5 * (h.pa + h.pb),
        lever_a: h.pa - a.body.position,
        lever_b: h.pb - b.body.position,
        normal,
        gap: h.gap,
        kinematics: GapKinematics::Point { owner },
        key: ContactKey { a: a.index as u32, b: Counterpart::Body(b.index), feature: h.feature },
    }
}

/// Sampled contacts between two pellets, both ways, patched and reduced. With `cache`, the
/// samples that can touch are kept across calls while the pair's relative pose allows it
/// (`sample_cache`): the same contacts, bit for bit. `kept` (sorted features) are the points
/// the reduction prefers (`patch::reduce`); `lean`: a rim crossing a convex side gives only its
/// refined deepest point.
#[allow(clippy::too_many_arguments)]
pub fn sampled_pair(
    a: Pellet<'_>,
    b: Pellet<'_>,
    max_gap: Real,
    cache: Option<&mut PairSamples>,
    kept: &[u32],
    lean: bool,
    out: &mut Vec<Contact>,
) {
    let mut ways = [OneWay::new(a, b, false), OneWay::new(b, a, true)];
    ways.iter_mut().for_each(|w| w.lean = lean);
    let lateral = lateral_hit(&a, &b);
    // Room for the pair's hits at once: growing from empty was 3-4 % of a cylinder bed (faces
    // on faces give hundreds of ~200-byte hits). With the cache, its candidates bound them.
    let mut hits = Vec::new();
    match cache {
        None => {
            hits.reserve(32);
            ways.iter().for_each(|way| way.collect(max_gap, &mut hits))
        }
        Some(cache) => {
            let poses = [(ways[0].m, ways[0].t), (ways[1].m, ways[1].t)];
            let reach = [lipschitz(b.shape), lipschitz(a.shape)];
            let radii = [a.geom.bounding_radius, b.geom.bounding_radius];
            if !cache.covers(&poses, &reach, &radii, max_gap) {
                let bound = max_gap + SAMPLE_CACHE_MARGIN * radii[0].min(radii[1]);
                cache.rebuild(poses, bound, |k, list| ways[k].candidates(bound, list));
            }
            hits.reserve(cache.candidates().iter().map(|list| list.len()).sum());
            for (way, list) in ways.iter().zip(cache.candidates()) {
                way.collect_from(list, max_gap, &mut hits);
            }
        }
    }
    hits.extend(lateral.filter(|h| h.gap <= max_gap));
    contacts_of(a, b, hits, kept, lean, out);
}

/// The contacts of a pair's hits: patched by normal and each patch reduced (`lean`: points
/// within `MERGE` of each other merged).
fn contacts_of(a: Pellet<'_>, b: Pellet<'_>, mut hits: Vec<Hit>, kept: &[u32], lean: bool, out: &mut Vec<Contact>) {
    let r_min = a.geom.bounding_radius.min(b.geom.bounding_radius);
    let merge = if lean { MERGE * r_min } else { 0.0 };
    for patch in patches(&mut hits) {
        let first = &hits[patch[0]];
        let (normal, owner) = (first.normal, first.owner);
        let band = NEAR_BAND * r_min;
        for k in reduce(&hits, &patch, &normal, band, kept, merge) {
            out.push(contact(&a, &b, &hits[k], normal, owner));
        }
    }
}

/// Re-evaluates the sampled contact with `feature` at the current poses (own normal), under
/// the same rules (`lean`) as the narrow phase that found it.
pub fn sampled_feature(a: Pellet<'_>, b: Pellet<'_>, feature: u32, lean: bool) -> Option<Contact> {
    let way = |src, dst, src_is_b| {
        let mut way = OneWay::new(src, dst, src_is_b);
        way.lean = lean;
        way
    };
    let h = if feature == LATERAL {
        lateral_hit(&a, &b)?
    } else if feature & SIDE_B != 0 {
        way(b, a, true).feature(feature)?
    } else {
        way(a, b, false).feature(feature)?
    };
    Some(contact(&a, &b, &h, h.normal, h.owner))
}

/// Sphere `s` (radius `r`) against any shape `o`: the centre in o's SDF, one point.
pub fn sphere_shape(s: Pellet<'_>, r: Real, o: Pellet<'_>, sphere_is_a: bool, max_gap: Real) -> Option<Contact> {
    let ro = rotation(&o);
    let c = s.body.position;
    let (phi, g) = eval(o.shape, &(ro.transpose() * (c - o.body.position)));
    let gap = phi - r;
    if gap > max_gap {
        return None;
    }
    let n_out = ro * g;
    let (a, b, h) = if sphere_is_a {
        let h = Hit {
            pa: c - n_out * r,
            pb: c - n_out * phi,
            normal: n_out,
            gap,
            feature: 0,
            owner: NormalOwner::B,
            wedge: None,
        };
        (s, o, h)
    } else {
        let n = -n_out;
        let h = Hit { pa: c + n * phi, pb: c + n * r, normal: n, gap, feature: 0, owner: NormalOwner::A, wedge: None };
        (o, s, h)
    };
    Some(contact(&a, &b, &h, h.normal, h.owner))
}
