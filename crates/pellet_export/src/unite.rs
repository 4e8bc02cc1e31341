//! One closed manifold surface from closed meshes that may overlap — the
//! pellets and the bridges joining them, or pellets that touch: their
//! union, by mesh booleans (the `manifold-rust` port of Manifold), so that
//! a mesher sees the real concave edge where a bridge meets a pellet and
//! no surface inside another solid.
//!
//! The union is evaluated as one balanced CSG tree (deterministic: the
//! same meshes in the same order give the same surface). Its volume is the
//! solid's, overlaps counted once; [`United::volume_in_tube`] clips it to
//! the tube's inside for the fluid volume a mesher should find.

use manifold_rust::csg_tree::CsgNode;
use manifold_rust::manifold::Manifold;
use manifold_rust::types::{Error as ManifoldError, MeshGL64, OpType};

use pellet_geom::math::Point;
use pellet_geom::TriMesh;

use crate::ExportError;

/// The union of several closed meshes.
pub struct United {
    solid: Manifold,
}

impl United {
    /// The union as one triangle mesh (outward triangles, shared vertices).
    pub fn mesh(&self) -> TriMesh {
        from_manifold(&self.solid)
    }

    /// The enclosed volume (overlaps counted once).
    pub fn volume(&self) -> f64 {
        self.solid.volume()
    }

    /// The volume of the union inside the closed mesh `tube` (its inside,
    /// e.g. [`crate::scene::tube_mesh`]): what bridges or pellets poking
    /// into the wall take from the fluid.
    pub fn volume_in_tube(&self, tube: &TriMesh) -> Result<f64, ExportError> {
        let tube = to_manifold(tube).map_err(|why| ExportError::Union(format!("the tube surface: {why}")))?;
        Ok(self.solid.intersection(&tube).volume())
    }

    /// How many separate pieces the union has (a bed joined by bridges
    /// may still be several).
    pub fn pieces(&self) -> usize {
        self.solid.decompose().len()
    }
}

/// The union of `meshes` (each closed and outward). `names` says what
/// each mesh is, for the error if one is not a closed manifold.
pub fn unite(meshes: &[&TriMesh], names: &dyn Fn(usize) -> String) -> Result<United, ExportError> {
    let mut leaves = Vec::with_capacity(meshes.len());
    for (k, m) in meshes.iter().enumerate() {
        let solid = to_manifold(m).map_err(|why| ExportError::Union(format!("{}: {why}", names(k))))?;
        leaves.push(CsgNode::leaf(solid.as_impl().clone()));
    }
    if leaves.is_empty() {
        return Ok(United { solid: Manifold::empty() });
    }
    let solid = Manifold::from_impl(CsgNode::op_n(OpType::Add, leaves).evaluate());
    match solid.status() {
        ManifoldError::NoError => Ok(United { solid }),
        status => Err(ExportError::Union(format!("the union of the surfaces failed ({status:?})"))),
    }
}

fn to_manifold(mesh: &TriMesh) -> Result<Manifold, String> {
    let gl = MeshGL64 {
        num_prop: 3,
        vert_properties: mesh.vertices.iter().flat_map(|p| [p.x, p.y, p.z]).collect(),
        tri_verts: mesh.triangles.iter().flat_map(|t| t.map(u64::from)).collect(),
        ..MeshGL64::default()
    };
    let solid = Manifold::from_mesh_gl64(&gl);
    match solid.status() {
        ManifoldError::NoError => Ok(solid),
        ManifoldError::NotManifold => {
            Err("the mesh is not a closed manifold (an edge without exactly one opposite)".into())
        }
        ManifoldError::NonFiniteVertex => Err("a vertex has a non-finite coordinate".into()),
        status => Err(format!("the mesh was refused ({status:?})")),
    }
}

fn from_manifold(solid: &Manifold) -> TriMesh {
    let gl = solid.get_mesh_gl64(-1);
    let stride = gl.num_prop as usize;
    let vertices = gl.vert_properties.chunks_exact(stride).map(|p| Point::new(p[0], p[1], p[2])).collect();
    let triangles = gl.tri_verts.chunks_exact(3).map(|t| [t[0] as u32, t[1] as u32, t[2] as u32]).collect();
    TriMesh { vertices, triangles }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{enclosed_volume, tube_mesh};
    use pellet_geom::{Pellet, Resolution, ShapeSpec};
    use std::f64::consts::PI;

    fn sphere_at(d_mm: f64, centre: [f64; 3]) -> TriMesh {
        let p = Pellet::build(ShapeSpec::Sphere { diameter_mm: d_mm }, Resolution::default()).unwrap();
        let mut m = p.mesh.clone();
        for v in &mut m.vertices {
            *v += pellet_geom::math::Vector::from(centre);
        }
        m
    }

    #[test]
    fn two_overlapping_spheres_count_their_lens_once() {
        // Spheres of radius r whose centres are a apart overlap in a lens
        // of volume π (4r + a)(2r − a)² / 12.
        let (r, a) = (0.005, 0.008);
        let (s1, s2) = (sphere_at(10.0, [0.0, 0.0, 0.0]), sphere_at(10.0, [a, 0.0, 0.0]));
        let u = unite(&[&s1, &s2], &|k| format!("sphere {k}")).unwrap();
        let each = enclosed_volume(&s1);
        // The mesh's own lens, scaled from the exact one by the mesh's volume deficit.
        let lens = PI * (4.0 * r + a) * (2.0 * r - a).powi(2) / 12.0 * each / (4.0 / 3.0 * PI * r.powi(3));
        let expected = 2.0 * each - lens;
        assert!((u.volume() - expected).abs() < 2e-3 * expected, "{} vs {expected}", u.volume());
        let mesh = u.mesh();
        mesh.check_closed().unwrap();
        assert!((enclosed_volume(&mesh) - u.volume()).abs() < 1e-9 * expected);
        assert_eq!(u.pieces(), 1);
    }

    #[test]
    fn apart_spheres_stay_two_pieces_and_a_bridge_joins_them() {
        let (s1, s2) = (sphere_at(10.0, [0.0, 0.0, 0.0]), sphere_at(10.0, [0.0102, 0.0, 0.0]));
        let two = unite(&[&s1, &s2], &|k| format!("sphere {k}")).unwrap();
        assert_eq!(two.pieces(), 2);
        assert!((two.volume() - 2.0 * enclosed_volume(&s1)).abs() < 1e-12);
        let contact = crate::Contact {
            pellet: 0,
            partner: crate::Partner::Pellet(1),
            point: Point::new(0.005, 0.0, 0.0),
            partner_point: Point::new(0.0052, 0.0, 0.0),
            normal: pellet_geom::math::Vector::x(),
            gap: 0.0002,
        };
        let bridge = crate::treatment::bridge_mesh(&contact, 0.001, 16);
        let joined = unite(&[&s1, &s2, &bridge], &|k| format!("surface {k}")).unwrap();
        assert_eq!(joined.pieces(), 1);
        joined.mesh().check_closed().unwrap();
        assert!(joined.volume() > two.volume());
        assert!(joined.volume() < two.volume() + enclosed_volume(&bridge));
    }

    #[test]
    fn the_part_inside_the_tube_excludes_what_pokes_through_the_wall() {
        // A sphere centred on a 20 mm tube's wall: about half inside.
        let s = sphere_at(10.0, [0.01, 0.0, 0.02]);
        let u = unite(&[&s], &|_| "sphere".into()).unwrap();
        let inside = u.volume_in_tube(&tube_mesh(0.01, 0.0, 0.04, 256)).unwrap();
        let half = 0.5 * enclosed_volume(&s);
        assert!(inside < half && inside > 0.8 * half, "{inside} vs {half}");
    }

    #[test]
    fn an_open_mesh_is_refused_by_name() {
        let mut s = sphere_at(10.0, [0.0, 0.0, 0.0]);
        s.triangles.pop();
        let err = unite(&[&s], &|k| format!("pellet {k}")).err().unwrap().to_string();
        assert!(err.starts_with("pellet 0: the mesh is not a closed manifold"), "{err}");
    }
}
