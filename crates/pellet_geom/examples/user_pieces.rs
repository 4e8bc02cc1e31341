//! How well V-HACD's pieces fill a nonconvex user mesh: the Raschig ring
//! imported as a plain mesh, union volume of its pieces (Monte Carlo) against
//! the mesh volume. `cargo run --release -p pellet_geom --example user_pieces`
use pellet_geom::math::Point;
use pellet_geom::parry_boundary::PieceSet;
use pellet_geom::{Pellet, Resolution, ShapeSpec};
use rand::{RngExt, SeedableRng};

fn main() {
    let ring = ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 };
    let mesh = Pellet::build(ring, Resolution::default()).expect("ring").mesh;
    let user = Pellet::from_mesh(mesh, "ring".into(), "m".into()).expect("import");
    let set = PieceSet::new(&user.pieces).expect("pieces");
    let r = user.bounding_radius;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let n = 200_000;
    let (mut inside_mesh, mut inside_pieces) = (0usize, 0usize);
    for _ in 0..n {
        let p = Point::new(rng.random_range(-r..r), rng.random_range(-r..r), rng.random_range(-r..r));
        inside_mesh += user.contains(&p) as usize;
        inside_pieces += set.contains(&p) as usize;
    }
    println!(
        "{} pieces; union of pieces / mesh volume = {:.4} (Monte Carlo, {n} points)",
        user.pieces.len(),
        inside_pieces as f64 / inside_mesh as f64
    );
}
