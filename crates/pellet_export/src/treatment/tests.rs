//! The treatments on small beds: bridges, shrink and caps.

use super::*;
use pellet_geom::{PlacedPellet, Resolution, ShapeSpec, Tube};

fn spheres(centres_mm: &[[Real; 3]]) -> Bed {
    let s = Pellet::build(ShapeSpec::Sphere { diameter_mm: 10.0 }, Resolution::default()).unwrap();
    Bed {
        tube: Tube { diameter: 0.06, lid_height: None },
        pellet_types: vec![s],
        pellets: centres_mm
            .iter()
            .map(|c| PlacedPellet { type_index: 0, position: c.map(|x| x * 1e-3), orientation: [1.0, 0.0, 0.0, 0.0] })
            .collect(),
    }
}

#[test]
fn a_bridge_joins_exactly_the_pairs_closer_than_the_gap() {
    // Pairs along x at surface gaps 0, 0.05, 0.15 (joined at 0.2 mm) and 0.25, 0.4 (not).
    let gaps = [0.0, 0.05, 0.15, 0.25, 0.4];
    let mut centres = Vec::new();
    for (k, g) in gaps.iter().enumerate() {
        let z = 6.0 + 12.0 * k as Real;
        centres.push([-10.0, 0.0, z]);
        centres.push([-10.0 + 10.0 + g, 0.0, z]);
    }
    let bed = spheres(&centres);
    let all: Vec<usize> = (0..bed.pellets.len()).collect();
    let t = Treatment { bridges: Some((0.2e-3, 2e-3)), ..Default::default() };
    let treated = apply(&bed, &all, (0.0, 0.06), &t, 1e-4).unwrap();
    let joined: Vec<(usize, Partner)> = treated.bridges.iter().map(|b| (b.contact.pellet, b.contact.partner)).collect();
    assert_eq!(joined, [(0, Partner::Pellet(1)), (2, Partner::Pellet(3)), (4, Partner::Pellet(5))]);
    for (b, g) in treated.bridges.iter().zip(gaps) {
        assert!((b.contact.gap - g * 1e-3).abs() < 1e-12);
        assert_eq!(b.mesh.check_closed().unwrap().components, 1);
        // The exact solid added: π rb² d − 2·(cap of the sphere inside the cylinder's section).
        let (r, rb, d): (Real, Real, Real) = (5e-3, 1e-3, 10e-3 + g * 1e-3);
        let exact = std::f64::consts::PI * rb * rb * d
            - 4.0 / 3.0 * std::f64::consts::PI * (r.powi(3) - (r * r - rb * rb).powf(1.5));
        assert!(
            (b.added_volume - exact).abs() < 0.01 * std::f64::consts::PI * rb * rb * 2e-3,
            "{} vs {exact}",
            b.added_volume
        );
    }
    let line = &treated.report.lines[0];
    assert_eq!((line.name, line.pellet_contacts, line.wall_contacts), ("bridges", 3, 0));
    // Without the closed form: gaps from vertex distances (never below
    // the true gap, so the 0.15 mm pair may be missed) and added volume
    // from mesh crossings, a little larger for the inscribed mesh.
    let mut mesh_only = bed.clone();
    mesh_only.pellet_types[0].closed_form = None;
    let by_mesh = apply(&mesh_only, &all, (0.0, 0.06), &t, 1e-4).unwrap();
    assert!((2..=3).contains(&by_mesh.bridges.len()), "{}", by_mesh.bridges.len());
    for (m, c) in by_mesh.bridges.iter().zip(&treated.bridges) {
        assert_eq!((m.contact.pellet, m.contact.partner), (c.contact.pellet, c.contact.partner));
        assert!(m.contact.gap >= c.contact.gap - 1e-12);
        let (vm, vc) = (m.added_volume, c.added_volume);
        assert!(vm >= vc * 0.98 && vm < vc * 1.3, "{vm} vs {vc}");
    }
}

#[test]
fn shrink_opens_contacts_and_caps_leave_the_gap() {
    let bed = spheres(&[[0.0, 0.0, 5.0], [0.0, 0.0, 15.0], [24.0, 0.0, 5.0]]);
    let all = [0, 1, 2];
    let shrink = apply(&bed, &all, (0.0, 0.02), &Treatment { shrink: Some(0.99), ..Default::default() }, 1e-4).unwrap();
    let line = &shrink.report.lines[0];
    // One pellet pair touching, one pellet 1 mm from the wall (not counted at 0.1 mm), two on the floor.
    assert_eq!((line.pellet_contacts, line.wall_contacts, line.floor_contacts), (1, 0, 2));
    let volume: Real = bed.pellet_types[0].properties.volume;
    let expected = 3.0 * volume * (1.0 - 0.99f64.powi(3)) / shrink.report.range_volume;
    assert!((line.porosity_change - expected).abs() < 1e-9 * expected.abs().max(1.0), "{line:?} vs {expected}");
    let caps = apply(&bed, &all, (0.0, 0.02), &Treatment { caps: Some(0.1e-3), ..Default::default() }, 1e-4).unwrap();
    let line = &caps.report.lines[0];
    assert_eq!((line.pellet_contacts, line.wall_contacts, line.floor_contacts), (1, 0, 2));
    assert!(line.porosity_change > 0.0);
    let lowest = caps.meshes[2].vertices.iter().map(|v| v.z).fold(Real::MAX, Real::min);
    assert!(lowest >= 0.1e-3 - 1e-12, "{lowest}");
    // The capped spheres are 0.1 mm apart: top of the lower at ≤ 9.95 mm, bottom of the upper ≥ 10.05.
    let top = caps.meshes[0].vertices.iter().map(|v| v.z).fold(Real::MIN, Real::max);
    let bottom = caps.meshes[1].vertices.iter().map(|v| v.z).fold(Real::MAX, Real::min);
    assert!(top <= 9.95e-3 + 1e-12 && bottom >= 10.05e-3 - 1e-12, "{top} {bottom}");
    assert!(caps.meshes[0].check_closed().is_ok());
}

/// Two rings of a settled 20-ring bed (D = 30 mm), the first's curved side in the mouth of
/// the second's bore: no plane separates them, so a cap cut along the contact plane
/// everywhere took 42 mm³, most of it the second's far rim (it reaches 1.9 mm past the
/// plane); cut only near the contact, the caps take 0.13 mm³ of the two.
#[test]
fn caps_at_a_rings_mouth_cut_only_near_the_contact() {
    let ring = Pellet::build(
        ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 },
        Resolution::default(),
    )
    .unwrap();
    let pose = |mm: [Real; 3], orientation| PlacedPellet { type_index: 0, position: mm.map(|x| x * 1e-3), orientation };
    let bed = Bed {
        // A wider tube than the bed's: no wall contacts.
        tube: Tube { diameter: 0.06, lid_height: None },
        pellet_types: vec![ring],
        pellets: vec![
            pose(
                [7.389757881349915, 5.409834332404802, 34.78638908750541],
                [-0.015062854907094744, 0.38706294441201294, -0.5056823636805197, -0.7708701152124354],
            ),
            pose(
                [6.275251623077952, -6.054976475403134, 38.24099341264039],
                [-0.38783801070933466, 0.2105800834784721, -0.8212382958644834, -0.3616702466291985],
            ),
        ],
    };
    let caps = Treatment { caps: Some(0.1e-3), ..Default::default() };
    let treated = apply(&bed, &[0, 1], (0.0, 0.05), &caps, 1e-4).unwrap();
    let line = &treated.report.lines[0];
    assert_eq!(line.pellet_contacts, 1);
    let removed = line.porosity_change * treated.report.range_volume;
    assert!(removed > 0.0 && removed < 0.2e-9, "{:.4} mm³ taken", removed * 1e9);
    for mesh in &treated.meshes {
        assert!(mesh.check_closed().is_ok());
    }
}
