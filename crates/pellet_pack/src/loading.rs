//! Loading schemes: where each new pellet appears and how it is oriented.
//!
//! The paper (Mohammadzadeh Moghaddam et al. 2018) drops pellets above the
//! bed in one column on the tube axis (the densest scheme and its default),
//! or in two or four columns equidistant from the axis; cylinders start
//! tilted (45° by default); random disturbances of position (up to a
//! fraction of dp) and orientation (up to an angle) mimic pouring. Two more
//! schemes mimic industrial practice:
//!
//! - **sock**: pellets lowered in a sock and released just above the bed
//!   surface at random places over the cross-section, in random
//!   orientations, with a low drop (default 0.5 dp): low impact speeds, a
//!   loose bed, as when a reactor tube is filled through a sock or by hand;
//! - **dense**: pellets rained uniformly over the whole cross-section from
//!   high above the surface (default 20 dp), as by a dense-loading device
//!   (a rotating spreader): high impact speeds and a surface that builds
//!   layer by layer, which gives dense beds.
//! - **batch**: every pellet at once, as a loose random cloud filling the
//!   tube from the floor up (bounding spheres apart, a quarter of the
//!   cloud's volume inside them), in random orientations, released from rest:
//!   the usual set-up of DEM settling studies. Its fall is
//!   short and all pellets move together, so a bed of hundreds of pellets
//!   needs about a second of simulated time instead of tens.
//!
//! Every random number comes from one ChaCha8 stream seeded by the run's
//! seed, so the same seed gives the same sequence of pellets on any machine.

use nalgebra::{Unit, UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// Share of the batch cloud's volume inside the pellets' bounding spheres.
pub const BATCH_FILL: f64 = 0.25;
/// Smallest gap between bounding spheres in the batch cloud, in bounding radii.
pub const BATCH_GAP: f64 = 0.02;

/// Height the batch cloud grows by per pellet (m) so that the bounding spheres (radius `rb`)
/// fill [`BATCH_FILL`] of a tube of radius `tube_radius`.
pub fn batch_height_per_pellet(rb: f64, tube_radius: f64) -> f64 {
    let area = std::f64::consts::PI * tube_radius.powi(2);
    4.0 / 3.0 * std::f64::consts::PI * rb.powi(3) / (area * BATCH_FILL)
}

/// Height (m) at which a pellet poured one at a time enters: `drop_height` above `bed_top`, or
/// `release_height` above the floor (the top of the tube it is poured into) if that is higher.
pub fn entry_height(bed_top: f64, drop_height: f64, release_height: Option<f64>) -> f64 {
    (bed_top + drop_height).max(release_height.unwrap_or(0.0))
}

/// Where and how pellets enter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LoadingScheme {
    /// One column on the tube axis.
    OneColumn,
    /// Two columns equidistant from the axis, used alternately.
    TwoColumns,
    /// Four columns equidistant from the axis, used in turn.
    FourColumns,
    /// Sock loading: low drop, random places and orientations.
    Sock,
    /// Dense loading: high drop, uniform over the cross-section.
    Dense,
    /// All pellets at once: a loose random cloud released from rest.
    Batch,
}

/// A new pellet: centroid position (m), orientation (body → world), velocity (m/s).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spawn {
    /// Centroid position (m).
    pub position: Vector3<f64>,
    /// Body → world rotation.
    pub orientation: UnitQuaternion<f64>,
}

/// The loading parameters a [`Feeder`] needs (SI).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeedParams {
    /// The scheme.
    pub scheme: LoadingScheme,
    /// Tilt of the pellet axis from vertical in the column schemes (rad).
    pub tilt: f64,
    /// Largest horizontal displacement from the scheme's position (m).
    pub position_jitter: f64,
    /// Largest rotation away from the scheme's orientation (rad).
    pub angle_jitter: f64,
    /// Height of the new pellet's centre above the bed top (m).
    pub drop_height: f64,
    /// Height of the new pellet's centre above the floor while the bed top is lower than it by
    /// more than `drop_height` (m): pellets poured in at the top of a tube.
    pub release_height: Option<f64>,
    /// Inner radius of the tube (m).
    pub tube_radius: f64,
    /// The pellet's bounding radius (m).
    pub bounding_radius: f64,
}

/// Produces the pellets of a run, one after the other.
pub struct Feeder {
    params: FeedParams,
    rng: ChaCha8Rng,
    count: u64,
}

impl Feeder {
    /// A feeder seeded with `seed`.
    pub fn new(params: FeedParams, seed: u64) -> Self {
        Feeder { params, rng: ChaCha8Rng::seed_from_u64(seed), count: 0 }
    }

    /// Largest distance of a centre from the axis that keeps the pellet
    /// clear of the wall (with a margin of 1 % of its bounding radius).
    fn max_offset(&self) -> f64 {
        (self.params.tube_radius - 1.01 * self.params.bounding_radius).max(0.0)
    }

    /// The scheme's nominal horizontal place for the next pellet.
    fn column_place(&mut self) -> Vector3<f64> {
        let p = &self.params;
        // Columns sit half-way between the axis and the wall clearance.
        let ring = 0.5 * self.max_offset();
        let n = self.count;
        match p.scheme {
            LoadingScheme::OneColumn => Vector3::zeros(),
            LoadingScheme::TwoColumns => {
                let a = std::f64::consts::PI * (n % 2) as f64;
                Vector3::new(ring * a.cos(), ring * a.sin(), 0.0)
            }
            LoadingScheme::FourColumns => {
                let a = std::f64::consts::FRAC_PI_2 * (n % 4) as f64;
                Vector3::new(ring * a.cos(), ring * a.sin(), 0.0)
            }
            LoadingScheme::Sock | LoadingScheme::Dense | LoadingScheme::Batch => {
                self.uniform_in_disc(self.max_offset())
            }
        }
    }

    fn uniform_in_disc(&mut self, radius: f64) -> Vector3<f64> {
        let r = radius * self.rng.random_range(0.0..1.0f64).sqrt();
        let a = self.rng.random_range(0.0..std::f64::consts::TAU);
        Vector3::new(r * a.cos(), r * a.sin(), 0.0)
    }

    fn uniform_rotation(&mut self) -> UnitQuaternion<f64> {
        // Shoemake's method: uniform over SO(3).
        let (u1, u2, u3): (f64, f64, f64) =
            (self.rng.random_range(0.0..1.0), self.rng.random_range(0.0..1.0), self.rng.random_range(0.0..1.0));
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let t = std::f64::consts::TAU;
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            b * (t * u3).cos(),
            a * (t * u2).sin(),
            a * (t * u2).cos(),
            b * (t * u3).sin(),
        ))
    }

    /// A rotation by a uniform random angle in [0, max] about a random axis.
    fn jitter_rotation(&mut self, max: f64) -> UnitQuaternion<f64> {
        if max <= 0.0 {
            return UnitQuaternion::identity();
        }
        let z: f64 = self.rng.random_range(-1.0..1.0);
        let a = self.rng.random_range(0.0..std::f64::consts::TAU);
        let s = (1.0 - z * z).sqrt();
        let axis = Unit::new_normalize(Vector3::new(s * a.cos(), s * a.sin(), z));
        UnitQuaternion::from_axis_angle(&axis, self.rng.random_range(0.0..=max))
    }

    /// The next pellet, at [`entry_height`] over `bed_top` (m).
    pub fn next(&mut self, bed_top: f64) -> Spawn {
        let p = self.params;
        let mut place = self.column_place();
        if p.position_jitter > 0.0
            && matches!(p.scheme, LoadingScheme::OneColumn | LoadingScheme::TwoColumns | LoadingScheme::FourColumns)
        {
            place += self.uniform_in_disc(p.position_jitter);
        }
        // Keep the pellet clear of the wall whatever the disturbance.
        let limit = self.max_offset();
        let r = place.norm();
        if r > limit {
            place *= limit / r;
        }
        let orientation = match p.scheme {
            LoadingScheme::Sock | LoadingScheme::Dense | LoadingScheme::Batch => self.uniform_rotation(),
            _ => {
                // Tilt about a horizontal axis; the paper's scheme 1 tilts by 45°.
                let tilt = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), p.tilt);
                self.jitter_rotation(p.angle_jitter) * tilt
            }
        };
        self.count += 1;
        let z = entry_height(bed_top, p.drop_height, p.release_height);
        Spawn { position: Vector3::new(place.x, place.y, z), orientation }
    }

    /// The batch scheme's cloud of `n` pellets: centres uniform over the cross-section (clear of
    /// the wall) and over a height that grows with the count so that the bounding spheres fill
    /// [`BATCH_FILL`] of the cloud's volume, at least [`BATCH_GAP`] bounding radii apart (no
    /// contact at release), lowest centre one bounding radius above the floor. Random sequential
    /// addition on a hash grid; deterministic for a seed.
    pub fn batch(&mut self, n: u32) -> Vec<Spawn> {
        let rb = self.params.bounding_radius;
        let offset = self.max_offset();
        let min_dist = (2.0 + BATCH_GAP) * rb;
        // Height per pellet at the target fill of the tube's cross-section.
        let per_pellet = batch_height_per_pellet(rb, self.params.tube_radius);
        let cell = min_dist;
        let mut grid: std::collections::HashMap<(i64, i64, i64), Vec<usize>> = std::collections::HashMap::new();
        let key =
            |p: &Vector3<f64>| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64, (p.z / cell).floor() as i64);
        let mut out: Vec<Spawn> = Vec::with_capacity(n as usize);
        let z0 = (1.0 + BATCH_GAP) * rb;
        let mut top = z0 + 2.0 * rb;
        for k in 0..n as usize {
            top = top.max(z0 + (k + 1) as f64 * per_pellet + 2.0 * rb);
            let position = loop {
                let xy = self.uniform_in_disc(offset);
                let z = self.rng.random_range(z0..=top);
                let p = Vector3::new(xy.x, xy.y, z);
                let (i, j, l) = key(&p);
                let clear = (-1..=1).all(|di| {
                    (-1..=1).all(|dj| {
                        (-1..=1).all(|dl| {
                            grid.get(&(i + di, j + dj, l + dl))
                                .is_none_or(|v| v.iter().all(|&q| (out[q].position - p).norm() >= min_dist))
                        })
                    })
                });
                if clear {
                    break p;
                }
                // A crowded cloud grows rather than searching forever.
                top += 1e-3 * rb;
            };
            grid.entry(key(&position)).or_default().push(k);
            let orientation = self.uniform_rotation();
            out.push(Spawn { position, orientation });
            self.count += 1;
        }
        out
    }

    /// How many pellets have been produced.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// Where the feeder is in its random stream and its sequence (for checkpoints).
    pub fn state(&self) -> FeederState {
        FeederState { word_pos: self.rng.get_word_pos(), count: self.count }
    }

    /// Continues from `state` (taken from a feeder with the same parameters and seed).
    pub fn set_state(&mut self, state: FeederState) {
        self.rng.set_word_pos(state.word_pos);
        self.count = state.count;
    }
}

/// A [`Feeder`]'s position: the word offset in its ChaCha8 stream and the pellets produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FeederState {
    /// Words of the random stream consumed.
    pub word_pos: u128,
    /// Pellets produced.
    pub count: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(scheme: LoadingScheme) -> FeedParams {
        FeedParams {
            scheme,
            tilt: 45f64.to_radians(),
            position_jitter: 0.008,
            angle_jitter: 45f64.to_radians(),
            drop_height: 0.03,
            release_height: None,
            tube_radius: 0.02,
            bounding_radius: 0.00707,
        }
    }

    /// A feeder set to another's state (a checkpoint) produces the same pellets from there on,
    /// column turn and random draws alike; a fresh one does not.
    #[test]
    fn a_restored_feeder_goes_on_with_the_same_pellets() {
        let mut a = Feeder::new(params(LoadingScheme::FourColumns), 9);
        for _ in 0..5 {
            a.next(0.01);
        }
        let mut b = Feeder::new(params(LoadingScheme::FourColumns), 9);
        let fresh = b.clone_state_free_next();
        b.set_state(a.state());
        let first = a.next(0.02);
        assert_ne!(fresh, first);
        assert_eq!(b.next(0.02), first);
        for _ in 0..5 {
            assert_eq!(a.next(0.02), b.next(0.02));
        }
        assert_eq!(a.state(), b.state());
    }

    impl Feeder {
        /// The next pellet of a copy of this feeder.
        fn clone_state_free_next(&self) -> Spawn {
            let mut copy = Feeder { params: self.params, rng: self.rng.clone(), count: self.count };
            copy.next(0.02)
        }
    }

    #[test]
    fn every_pellet_starts_clear_of_the_wall_and_above_the_bed() {
        for scheme in [
            LoadingScheme::OneColumn,
            LoadingScheme::TwoColumns,
            LoadingScheme::FourColumns,
            LoadingScheme::Sock,
            LoadingScheme::Dense,
        ] {
            let mut f = Feeder::new(params(scheme), 3);
            for _ in 0..500 {
                let s = f.next(0.05);
                assert!(s.position.xy().norm() + 0.00707 < 0.02, "{scheme:?}: {:?}", s.position);
                assert!((s.position.z - 0.08).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn one_column_without_disturbance_is_on_the_axis_tilted_45_degrees() {
        let mut p = params(LoadingScheme::OneColumn);
        p.position_jitter = 0.0;
        p.angle_jitter = 0.0;
        let s = Feeder::new(p, 1).next(0.0);
        assert_eq!(s.position.xy().norm(), 0.0);
        let axis = s.orientation * Vector3::z();
        assert!((axis.z.acos().to_degrees() - 45.0).abs() < 1e-12);
    }

    #[test]
    fn disturbances_stay_within_their_bounds_and_use_them() {
        let mut p = params(LoadingScheme::OneColumn);
        p.tube_radius = 1.0; // no wall clamp in this test
        let mut f = Feeder::new(p, 9);
        let (mut max_r, mut max_angle) = (0.0f64, 0.0f64);
        let tilt = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), p.tilt);
        for _ in 0..2000 {
            let s = f.next(0.0);
            max_r = max_r.max(s.position.xy().norm());
            max_angle = max_angle.max(s.orientation.angle_to(&tilt));
        }
        assert!(max_r <= 0.008 && max_r > 0.0079, "{max_r}");
        assert!(max_angle <= 45f64.to_radians() + 1e-12 && max_angle > 44f64.to_radians(), "{max_angle}");
    }

    #[test]
    fn columns_alternate_and_the_seed_fixes_the_sequence() {
        let mut p = params(LoadingScheme::FourColumns);
        p.position_jitter = 0.0;
        let mut f = Feeder::new(p, 5);
        let places: Vec<_> = (0..8).map(|_| f.next(0.0).position).collect();
        assert!((places[0] - places[4]).norm() < 1e-15);
        assert!((places[0] + places[2]).xy().norm() < 1e-15);
        assert!((places[0].xy().norm() - places[1].xy().norm()).abs() < 1e-15);
        let again: Vec<_> = {
            let mut g = Feeder::new(p, 5);
            (0..8).map(|_| g.next(0.0).orientation).collect()
        };
        let mut h = Feeder::new(p, 5);
        assert!(again.iter().all(|q| *q == h.next(0.0).orientation));
        let mut other = Feeder::new(p, 6);
        assert_ne!(other.next(0.0).orientation, again[0]);
    }

    #[test]
    fn the_batch_cloud_is_clear_of_wall_floor_and_itself_and_fills_a_quarter() {
        let p = params(LoadingScheme::Batch);
        let cloud = Feeder::new(p, 4).batch(300);
        assert_eq!(cloud.len(), 300);
        let rb = p.bounding_radius;
        for (i, s) in cloud.iter().enumerate() {
            assert!(s.position.xy().norm() + rb < p.tube_radius, "{i}: {:?}", s.position);
            assert!(s.position.z - rb >= BATCH_GAP * rb - 1e-15, "{i}: {:?}", s.position);
            for t in &cloud[..i] {
                assert!((s.position - t.position).norm() >= (2.0 + BATCH_GAP) * rb);
            }
        }
        // The bounding spheres fill about BATCH_FILL of the cloud's cylinder.
        let top = cloud.iter().map(|s| s.position.z).fold(0.0, f64::max) + rb;
        let fill = 300.0 * 4.0 / 3.0 * std::f64::consts::PI * rb.powi(3)
            / (std::f64::consts::PI * p.tube_radius.powi(2) * top);
        assert!(fill > 0.8 * BATCH_FILL && fill < BATCH_FILL, "fill {fill}");
        let again = Feeder::new(p, 4).batch(300);
        assert!(cloud.iter().zip(&again).all(|(a, b)| a == b));
        assert_ne!(Feeder::new(p, 5).batch(1)[0], cloud[0]);
    }

    /// With a release height, pellets enter there until the bed comes within the drop height
    /// of it, then the drop height above the bed; the draws are those of the plain feeder.
    #[test]
    fn pellets_enter_at_the_release_height_until_the_bed_reaches_it() {
        let plain = params(LoadingScheme::OneColumn);
        let poured = FeedParams { release_height: Some(0.15), ..plain };
        let (mut a, mut b) = (Feeder::new(plain, 3), Feeder::new(poured, 3));
        for (bed_top, z) in [(0.0, 0.15), (0.1, 0.15), (0.12, 0.15), (0.13, 0.16)] {
            let (x, y) = (a.next(bed_top), b.next(bed_top));
            assert!((y.position.z - z).abs() < 1e-15, "bed top {bed_top}: {}", y.position.z);
            assert_eq!((x.position.xy(), x.orientation), (y.position.xy(), y.orientation));
        }
    }
}
