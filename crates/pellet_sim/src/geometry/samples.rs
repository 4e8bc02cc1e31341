//! Body-frame surface samples of each pellet type (`docs/engine.md`, "Contact generation"),
//! grouped into clusters for the Lipschitz cull, and the rim circles used for rim–rim
//! refinement and the wall fast paths.
//!
//! Cylinders and rings get exact samples on their rims, caps and lateral surfaces (the pellet
//! file's Loop-subdivided mesh rounds the rims off, so its vertices are not on the true edges);
//! mesh shapes use the samples they were given (normally the mesh vertices).

use crate::math::{axial_distance, Real, Vec3};
use crate::shape::{BodyType, ShapeDesc};
use std::f64::consts::TAU;

/// Samples per rim circle of the outer radius (spacing ≈ 0.025 d for D = H).
pub const RIM_SAMPLES: usize = 128;

/// A rim circle: radius `radius` in the plane z = `z` (body frame).
#[derive(Debug, Clone, PartialEq)]
pub struct Rim {
    /// Height of the circle, m.
    pub z: Real,
    /// Radius, m.
    pub radius: Real,
    /// Index of its first sample; samples `start..start + count` are at angles 2πk/count.
    pub start: usize,
    /// Number of samples on it.
    pub count: usize,
    /// Whether it is an outer rim (the ones that can touch a plane or the tube wall).
    pub outer: bool,
}

/// A group of nearby samples with its bounding sphere.
#[derive(Debug, Clone, PartialEq)]
pub struct Cluster {
    /// Centre, body frame, m.
    pub centre: Vec3,
    /// Radius about the centre, m.
    pub radius: Real,
    /// Sample indices.
    pub members: Vec<u32>,
}

/// Derived collision data of one body type (rebuilt from the type, never serialised).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TypeGeometry {
    /// Surface samples, body frame, m.
    pub samples: Vec<Vec3>,
    /// For each sample, its outward normal cone as two unit vectors: equal on a smooth face,
    /// the two face normals (perpendicular) on a rim, the arc between them being the cone.
    pub cones: Vec<(Vec3, Vec3)>,
    /// For each sample, the rim it lies on (`u32::MAX` if none).
    pub rim_of: Vec<u32>,
    /// Rim circles.
    pub rims: Vec<Rim>,
    /// Clusters over all samples.
    pub clusters: Vec<Cluster>,
    /// Bounding radius of the type, m.
    pub bounding_radius: Real,
}

impl TypeGeometry {
    /// Builds the samples of `ty`.
    pub fn new(ty: &BodyType) -> Self {
        let mut g = TypeGeometry { bounding_radius: ty.bounding_radius_m, ..Default::default() };
        match &ty.shape {
            ShapeDesc::Sphere { .. } => {}
            ShapeDesc::Cylinder { radius, half_height } => {
                let (r, h) = (*radius, *half_height);
                for z in [-h, h] {
                    g.rim(z, r, RIM_SAMPLES, true);
                    for f in [0.25, 0.5, 0.75] {
                        g.ring(z, f * r, 32);
                    }
                    g.samples.push(Vec3::new(0.0, 0.0, z));
                }
                g.lateral(r, h, 64);
            }
            ShapeDesc::HollowCylinder { inner_radius, outer_radius, half_height } => {
                let (ri, ro, h) = (*inner_radius, *outer_radius, *half_height);
                let n_in = ((RIM_SAMPLES as Real * ri / ro).round() as usize).max(32);
                for z in [-h, h] {
                    g.rim(z, ro, RIM_SAMPLES, true);
                    g.rim(z, ri, n_in, false);
                    for f in [1.0 / 3.0, 2.0 / 3.0] {
                        g.ring(z, ri + f * (ro - ri), 64);
                    }
                }
                g.lateral(ro, h, 64);
                g.lateral(ri, h, (n_in / 2).max(16));
            }
            ShapeDesc::Mesh { samples, .. } => g.samples.clone_from(samples),
        }
        g.cones = g.samples.iter().map(|p| cone(&ty.shape, p)).collect();
        g.rim_of.resize(g.samples.len(), u32::MAX);
        for (k, rim) in g.rims.iter().enumerate() {
            g.rim_of[rim.start..rim.start + rim.count].iter_mut().for_each(|x| *x = k as u32);
        }
        g.clusters = clusters(&g.samples, 0.5 * ty.bounding_radius_m);
        g
    }

    fn ring(&mut self, z: Real, r: Real, n: usize) {
        self.samples.extend((0..n).map(|k| {
            let t = TAU * (k as Real + 0.5) / n as Real;
            Vec3::new(r * t.cos(), r * t.sin(), z)
        }));
    }

    fn rim(&mut self, z: Real, radius: Real, count: usize, outer: bool) {
        let start = self.samples.len();
        self.samples.extend((0..count).map(|k| rim_point(radius, z, TAU * k as Real / count as Real)));
        self.rims.push(Rim { z, radius, start, count, outer });
    }

    /// Four rings on the lateral surface between the rims.
    fn lateral(&mut self, r: Real, h: Real, n: usize) {
        for k in 1..5 {
            self.ring(-h + 2.0 * h * k as Real / 5.0, r, n);
        }
    }

    /// Sample spacing along rim `k`, m.
    pub fn rim_spacing(&self, k: usize) -> Real {
        TAU * self.rims[k].radius / self.rims[k].count as Real
    }
}

/// Outward normal cone of the surface at sample `p`, classified by where `p` lies.
fn cone(shape: &ShapeDesc, p: &Vec3) -> (Vec3, Vec3) {
    let rho = p.x.hypot(p.y);
    let er = if rho > 0.0 { Vec3::new(p.x / rho, p.y / rho, 0.0) } else { Vec3::x() };
    let ez = Vec3::new(0.0, 0.0, p.z.signum());
    let (h, radial) = match shape {
        ShapeDesc::Cylinder { radius, half_height } => {
            (*half_height, ((rho - radius).abs() <= 1e-9 * radius).then_some(er))
        }
        ShapeDesc::HollowCylinder { inner_radius, outer_radius, half_height } => {
            let e = if (rho - outer_radius).abs() <= 1e-9 * outer_radius {
                Some(er)
            } else if (rho - inner_radius).abs() <= 1e-9 * inner_radius {
                Some(-er)
            } else {
                None
            };
            (*half_height, e)
        }
        ShapeDesc::Sphere { .. } => return (p.normalize(), p.normalize()),
        ShapeDesc::Mesh { grid, .. } => {
            let g = grid.eval(p).1;
            return (g, g);
        }
    };
    let on_cap = (p.z.abs() - h).abs() <= 1e-9 * h;
    match (radial, on_cap) {
        (Some(e), true) => (e, ez),
        (Some(e), false) => (e, e),
        (None, _) => (ez, ez),
    }
}

/// The best alignment of direction `m` with a normal cone: max over the cone of m·n.
pub fn cone_alignment(m: &Vec3, cone: &(Vec3, Vec3)) -> Real {
    let (a, b) = (m.dot(&cone.0), m.dot(&cone.1));
    if cone.0 != cone.1 && a > 0.0 && b > 0.0 {
        axial_distance(a, b)
    } else {
        a.max(b)
    }
}

/// Point of a rim circle at angle `t`.
pub fn rim_point(radius: Real, z: Real, t: Real) -> Vec3 {
    Vec3::new(radius * t.cos(), radius * t.sin(), z)
}

/// Groups samples by a body-frame grid of cell `cell` (sorted cell order: deterministic).
fn clusters(samples: &[Vec3], cell: Real) -> Vec<Cluster> {
    let key = |p: &Vec3| {
        let f = |v: Real| (v / cell).floor() as i64;
        (f(p.x), f(p.y), f(p.z))
    };
    let mut order: Vec<(i64, i64, i64, u32)> = samples
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let (a, b, c) = key(p);
            (a, b, c, i as u32)
        })
        .collect();
    order.sort_unstable();
    let mut out: Vec<Cluster> = Vec::new();
    let mut last = None;
    for (a, b, c, i) in order {
        if last != Some((a, b, c)) {
            out.push(Cluster { centre: Vec3::zeros(), radius: 0.0, members: Vec::new() });
            last = Some((a, b, c));
        }
        out.last_mut().expect("just pushed").members.push(i);
    }
    for cl in &mut out {
        let n = cl.members.len() as Real;
        cl.centre = cl.members.iter().map(|&i| samples[i as usize]).sum::<Vec3>() / n;
        cl.radius = cl.members.iter().map(|&i| (samples[i as usize] - cl.centre).norm()).fold(0.0, Real::max);
    }
    out
}

/// Collision data of every registered type, rebuilt when the types change (it is not part of
/// the serialised world).
#[derive(Debug, Clone, Default)]
pub struct GeometryCache {
    /// One entry per registered type.
    pub types: Vec<TypeGeometry>,
}

impl PartialEq for GeometryCache {
    /// Derived data: two worlds with equal types have equal caches once rebuilt.
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl GeometryCache {
    /// Rebuilds the entries missing for `types`.
    pub fn sync(&mut self, types: &[BodyType]) {
        if self.types.len() > types.len() {
            self.types.clear();
        }
        for ty in &types[self.types.len()..] {
            self.types.push(TypeGeometry::new(ty));
        }
    }
}
