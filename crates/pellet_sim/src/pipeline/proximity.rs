//! Which pairs and walls are near, how fast they can close, and how long the rest may fly
//! freely: the inputs of the substep rule δt = min(0.2λ/v_max, δt_cap, t_safe).

use super::world::World;
use crate::body::Body;
use crate::container::{Container, WallId};
use crate::geometry::pair_cache::PairCache;
use crate::math::{axial_distance, Real, Vec3};
use crate::params::ApproachBound;
use crate::shape::ShapeDesc;

/// The broad phase's skin as a factor of λ: its candidates are reused until a body has moved
/// (or its swept radius grown) by this much.
const PAIR_SKIN_FACTOR: Real = 1.0;

/// Near pairs and walls of one substep.
pub(crate) struct Proximity {
    /// Body pairs whose bounding spheres are within λ.
    pub pairs: Vec<(usize, usize)>,
    /// Bodies within λ of a wall.
    pub walls: Vec<(usize, WallId)>,
    /// Time before any other pair or wall can come within λ/2, s.
    pub t_safe: Real,
    /// Upper bound on the closing speed of any near pair or wall, m/s.
    pub v_max: Real,
}

impl World {
    /// λ, the proximity distance, m.
    pub(crate) fn lambda(&self) -> Real {
        self.params.proximity_factor * 0.5 * self.reference_size()
    }

    /// Near pairs/walls (bounding gap ≤ λ), their closing-speed bound, and the time before any
    /// other pair can come within λ/2. `horizon` inflates the broad phase by each body's travel.
    pub(crate) fn proximity(&self, broad: &mut PairCache, horizon: Real) -> Proximity {
        let lambda = self.lambda();
        let g = self.params.gravity.norm();
        let dt_cap = self.params.acceleration.dt_cap;
        let normal = self.params.acceleration.approach_bound == ApproachBound::Normal;
        let centres: Vec<Vec3> = self.bodies.iter().map(|b| b.position).collect();
        let radii: Vec<Real> =
            self.bodies.iter().map(|b| b.bounding_radius + lambda + b.velocity().norm() * horizon).collect();
        // A sphere's rotation moves none of its surface: its gaps close only by translation.
        let round = |k: usize| matches!(self.types[self.bodies[k].type_id.0 as usize].shape, ShapeDesc::Sphere { .. });
        // ω·ρ per body, once: per pair end (ω = I⁻¹L through R I⁻¹ Rᵀ) it was 3 % of a pour.
        let spins: Vec<Real> = self.bodies.iter().map(|b| b.angular_velocity().norm() * b.bounding_radius).collect();
        let spin = |k: usize| spins[k];
        // Pairs that touch now or may within the substep keep the speed bound (`Speed`), which also
        // limits how far their contacts slip per substep (sliding and spin). Measured with 40
        // spheres in a 40 mm tube, seeds 1–6: the closing speed alone for touching spheres too
        // packed them to a mean porosity of 0.4456, against 0.4674 with the speed bound and
        // 0.468 with the closing speed alone at δt_cap/4, so it under-resolved friction. With
        // this split, seeds 1–18: 0.4583 ± 0.0039 against 0.4602 ± 0.0036 (the speed bound).
        let touching = self.params.contact_distance_factor * self.reference_size() + 0.2 * lambda;
        let mut p = Proximity { pairs: Vec::new(), walls: Vec::new(), t_safe: Real::INFINITY, v_max: 0.0 };
        for &(i, j) in broad.overlapping_pairs(&centres, &radii, PAIR_SKIN_FACTOR * lambda) {
            let (i, j) = (i as usize, j as usize);
            let (bi, bj) = (&self.bodies[i], &self.bodies[j]);
            let c = bi.position - bj.position;
            let distance = c.norm();
            let gap = distance - bi.bounding_radius - bj.bounding_radius;
            let v = bi.velocity() - bj.velocity();
            // At constant velocities the centre distance |c + v t| is convex in t, so the
            // bounding spheres close at most at its initial rate −v·ĉ (spin moves neither).
            let closing = if normal && distance > 0.0 { (-v.dot(&c) / distance).max(0.0) } else { v.norm() };
            if gap <= lambda {
                p.pairs.push((i, j));
                // Inside the bounding spheres a non-sphere's contact normal can point anywhere
                // and its spin sweeps its surface: the whole bound counts.
                let bound = if normal && round(i) && round(j) && gap > touching {
                    closing
                } else {
                    v.norm() + (spin(i) + spin(j))
                };
                p.v_max = p.v_max.max(bound);
            } else if closing > 0.0 {
                p.t_safe = p.t_safe.min((gap - 0.5 * lambda) / closing);
            }
        }
        for (k, b) in self.bodies.iter().enumerate() {
            self.container.wall_gaps(&b.position, b.bounding_radius, |wall, gap| {
                if gap <= lambda {
                    let speed = b.velocity().norm() + spin(k);
                    let v = if normal && gap > touching {
                        wall_closing(&self.container, wall, b, round(k), dt_cap) + if round(k) { 0.0 } else { spin(k) }
                    } else {
                        speed
                    };
                    p.walls.push((k, wall));
                    p.v_max = p.v_max.max(v + g * dt_cap);
                } else {
                    // Free flight can last far longer than δt_cap: only bounds valid over any
                    // time (a straight line's distance to the axis changes at most at |v_xy|).
                    let v = match (normal, wall) {
                        (true, WallId::Floor) => (-b.velocity().z).max(0.0),
                        (true, WallId::Tube) => b.velocity().xy().norm(),
                        _ => b.velocity().norm(),
                    };
                    let s = gap - 0.5 * lambda;
                    let t = if g > 0.0 {
                        (-v + (v * v + 2.0 * g * s).sqrt()) / g
                    } else if v > 0.0 {
                        s / v
                    } else {
                        Real::INFINITY
                    };
                    p.t_safe = p.t_safe.min(t);
                }
            });
        }
        p
    }
}

/// Upper bound on how fast body `b`'s translation closes its bounding gap to a wall: the
/// velocity into the wall; for the curved tube wall also what tangential motion adds over one
/// substep of at most `dt_cap` (second order) and the turn of the wall normal across the body (the nearest
/// point of a body that is not `round` need not lie on the centre's radius).
pub(crate) fn wall_closing(container: &Container, wall: WallId, b: &Body, round: bool, dt_cap: Real) -> Real {
    let v = b.velocity();
    match wall {
        WallId::Floor => (-v.z).max(0.0),
        WallId::Lid => v.z.max(0.0),
        WallId::Tube => {
            let r = axial_distance(b.position.x, b.position.y);
            let vxy = Vec3::new(v.x, v.y, 0.0);
            if r <= 1e-12 {
                return vxy.norm();
            }
            let radial = Vec3::new(b.position.x / r, b.position.y / r, 0.0);
            let vr = vxy.dot(&radial);
            let vt = (vxy - vr * radial).norm();
            let turn = if round {
                0.0
            } else {
                (b.bounding_radius / (container.tube_radius - b.bounding_radius).max(1e-12)).min(1.0)
            };
            // |x + v t| ≤ r + v_r t + (v_t t)²/(2(r + v_r t)), with r + v_r t ≥ r − |v_r| δt_cap.
            let inner = r - vr.abs() * dt_cap;
            let curving = if inner > 0.0 { (vt * vt * dt_cap / (2.0 * inner)).min(vt) } else { vt };
            vr.max(0.0) + curving + vt * turn
        }
        WallId::Plane(_) => v.norm(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{EngineParams, Material, WallMaterial};
    use crate::shape::BodyType;
    use crate::{Quat, TypeId};

    const R: Real = 0.005;

    fn world(bound: ApproachBound, cylinder: bool) -> (World, TypeId) {
        let mut params = EngineParams::paper();
        params.acceleration.approach_bound = bound;
        let mat = Material { density: 2000.0, cor: 0.5, friction: 0.3 };
        let wall = WallMaterial { cor: 0.5, friction: 0.3 };
        let mut w = World::new(Container::tube(0.04).unwrap(), mat, wall, params).unwrap();
        let ty = if cylinder { BodyType::solid_cylinder(R, R) } else { BodyType::solid_sphere(R) };
        let t = w.register_type(ty.unwrap()).unwrap();
        (w, t)
    }

    fn v_max(w: &World) -> Real {
        w.proximity(&mut PairCache::default(), w.params.acceleration.dt_cap).v_max
    }

    /// Two spheres falling side by side at 2 m/s, 0.3 mm from each other and from the tube
    /// wall (near, not touching), high above the floor: nothing closes except by gravity over
    /// a substep, whatever the spin.
    #[test]
    fn bodies_falling_together_beside_the_wall_do_not_shrink_the_substep() {
        let fall = Vec3::new(0.0, 0.0, -2.0);
        for (bound, expect_fast) in [(ApproachBound::Normal, false), (ApproachBound::Speed, true)] {
            let (mut w, t) = world(bound, false);
            w.add_body(t, Vec3::new(0.015 - 3e-4, 0.0, 0.1), Quat::identity(), fall, Vec3::zeros()).unwrap();
            w.add_body(t, Vec3::new(0.005 - 6e-4, 0.0, 0.1), Quat::identity(), fall, Vec3::new(0.0, 50.0, 0.0))
                .unwrap();
            let p = w.proximity(&mut PairCache::default(), w.params.acceleration.dt_cap);
            assert_eq!((p.pairs.len(), p.walls.len()), (1, 1));
            let gravity_part = w.params.gravity.norm() * w.params.acceleration.dt_cap;
            if expect_fast {
                assert!(p.v_max >= 2.0, "{bound:?}: {}", p.v_max);
            } else {
                assert!(p.v_max <= gravity_part + 1e-12, "{bound:?}: {}", p.v_max);
            }
        }
    }

    /// Far pairs limit the free flight by how fast their bounding spheres close, which spin
    /// does not change: a spinning cylinder 2 mm away, closing at 1 m/s head-on, gives
    /// t_safe = (gap − λ/2) / 1 m/s with either bound.
    #[test]
    fn spin_does_not_shorten_the_free_flight() {
        for bound in [ApproachBound::Normal, ApproachBound::Speed] {
            let (mut w, t) = world(bound, true);
            let rho = {
                w.add_body(t, Vec3::new(0.0, 0.0, 0.1), Quat::identity(), Vec3::zeros(), Vec3::new(0.0, 30.0, 0.0))
                    .unwrap();
                w.bodies[0].bounding_radius
            };
            let gap = 0.002;
            let x = Vec3::new(0.0, 0.0, 0.1 + 2.0 * rho + gap);
            w.add_body(t, x, Quat::identity(), Vec3::new(0.0, 0.0, -1.0), Vec3::zeros()).unwrap();
            let p = w.proximity(&mut PairCache::default(), 0.01);
            assert!(p.pairs.is_empty());
            let expect = gap - 0.5 * w.lambda();
            assert!((p.t_safe - expect).abs() < 1e-12, "{bound:?}: {} vs {expect}", p.t_safe);
        }
    }

    /// Touching spheres keep the whole bound: their contacts slip at the sliding speed plus the
    /// spin, and the substep must resolve that slip (a sliding pair and a sphere rolling along
    /// the wall, both with zero closing speed).
    #[test]
    fn touching_spheres_keep_their_slip_in_the_bound() {
        let (mut w, t) = world(ApproachBound::Normal, false);
        w.add_body(t, Vec3::new(-0.005, 0.0, 0.1), Quat::identity(), Vec3::new(0.0, 0.0, 1.0), Vec3::zeros()).unwrap();
        w.add_body(t, Vec3::new(0.005 + 1e-6, 0.0, 0.1), Quat::identity(), Vec3::zeros(), Vec3::zeros()).unwrap();
        assert!((v_max(&w) - 1.0).abs() < 0.01, "sliding pair: {}", v_max(&w));
        let (mut w, t) = world(ApproachBound::Normal, false);
        let roll = Vec3::new(0.0, 100.0, 0.0);
        w.add_body(t, Vec3::new(0.015 - 1e-6, 0.0, 0.1), Quat::identity(), Vec3::zeros(), roll).unwrap();
        assert!(v_max(&w) >= 100.0 * R, "rolling along the wall: {}", v_max(&w));
    }

    /// A cylinder's spin sweeps its corners: its ω·ρ still counts under the normal bound.
    #[test]
    fn a_spinning_cylinder_keeps_its_rotational_term() {
        let (mut w, t) = world(ApproachBound::Normal, true);
        w.add_body(t, Vec3::new(0.0, 0.0, 0.1), Quat::identity(), Vec3::zeros(), Vec3::new(0.0, 0.0, 0.0)).unwrap();
        let spin = Vec3::new(20.0, 0.0, 0.0);
        let rho = w.bodies[0].bounding_radius;
        w.add_body(t, Vec3::new(0.0, 0.0, 0.1 + 2.0 * rho + 1e-5), Quat::identity(), Vec3::zeros(), spin).unwrap();
        assert!((v_max(&w) - 20.0 * rho).abs() < 1e-9, "{} vs {}", v_max(&w), 20.0 * rho);
    }

    /// The bound is safe: over any substep up to the cap, at constant velocities, no near pair
    /// of spheres and no sphere near the tube wall or floor closes its gap by more than
    /// v_max·δt. Random states, a fixed seed.
    #[test]
    fn the_normal_bound_covers_every_closing_of_spheres() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as Real / (1u64 << 53) as Real
        };
        let tube = 0.02;
        let (mut tried, mut near, mut far) = (0, 0, 0);
        for _ in 0..8000 {
            let (mut w, t) = world(ApproachBound::Normal, false);
            let mut centred = || Vec3::new(uniform() - 0.5, uniform() - 0.5, uniform() - 0.5);
            let dir = centred().normalize();
            let (va, vb) = (centred() * 6.0, centred() * 6.0);
            let a = Vec3::new(tube - R - 1e-4 * uniform(), 0.0, R + 1e-4 * uniform());
            let b = a - dir * (2.0 * R + 4e-4 * uniform());
            if b.x.hypot(b.y) > tube - R || b.z < R {
                continue;
            }
            tried += 1;
            w.add_body(t, a, Quat::identity(), va, Vec3::zeros()).unwrap();
            w.add_body(t, b, Quat::identity(), vb, Vec3::zeros()).unwrap();
            let p = w.proximity(&mut PairCache::default(), w.params.acceleration.dt_cap);
            // Gravity's share of a wall's bound is not in these straight-line motions.
            let (pair_bound, wall_bound) = (p.v_max, p.v_max - w.params.gravity.norm() * w.params.acceleration.dt_cap);
            let dt = w.params.acceleration.dt_cap * uniform();
            let (a1, b1) = (a + va * dt, b + vb * dt);
            let gap = |x: Vec3, y: Vec3| (x - y).norm() - 2.0 * R;
            let floor = |x: Vec3| x.z - R;
            let side = |x: Vec3| tube - x.x.hypot(x.y) - R;
            let lambda = w.lambda();
            for (before, after, bound) in [
                (gap(a, b), gap(a1, b1), pair_bound),
                (floor(a), floor(a1), wall_bound),
                (floor(b), floor(b1), wall_bound),
                (side(a), side(a1), wall_bound),
                (side(b), side(b1), wall_bound),
            ] {
                if before <= lambda {
                    assert!(
                        before - after <= bound * dt * (1.0 + 1e-9) + 1e-15,
                        "closed {} > {}",
                        before - after,
                        bound * dt
                    );
                    near += 1;
                }
            }
            // Far gaps stay above λ/2 for t_safe, which can be much longer than a substep.
            let flight = p.t_safe.min(0.05);
            let (a1, b1) = (a + va * flight, b + vb * flight);
            for (before, after) in [
                (gap(a, b), gap(a1, b1)),
                (floor(a), floor(a1)),
                (floor(b), floor(b1)),
                (side(a), side(a1)),
                (side(b), side(b1)),
            ] {
                if before > lambda {
                    assert!(after >= 0.5 * lambda * (1.0 - 1e-9), "far gap {before} fell to {after} within t_safe");
                    far += 1;
                }
            }
        }
        assert!(tried > 1000 && near > 3000 && far > 100, "{tried} states inside the tube, {near} near, {far} far");
    }
}
