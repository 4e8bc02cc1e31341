//! The optional viewer channels of a trajectory, in Foxglove's well-known
//! schemas, so that a run replays in Foxglove or Lichtblick's 3D panel.
//!
//! Two topics, JSON-encoded (`json` messages, `jsonschema` schemas, which both
//! viewers read without plug-ins):
//! - `/foxglove/scene` (`foxglove.SceneUpdate`): the tube (frame `world`) at
//!   t = 0, and each pellet's shape once, when it enters, as an entity
//!   `pellet-<i>` locked to the frame `pellet-<i>`. Spheres and cylinders
//!   are exact primitives; other shapes are triangle lists of the coarse
//!   control mesh (level 0), to keep the archive small.
//! - `/foxglove/transforms` (`foxglove.FrameTransforms`): with every pose
//!   frame, the transform `world` → `pellet-<i>` of each pellet.
//!
//! Lengths in metres (Foxglove's unit), quaternions (x, y, z, w) as Foxglove
//! spells them; log time = simulated time. The schemas written are the subset
//! of Foxglove's that these messages use, with Foxglove's field names.

use serde_json::{json, Value};

use pellet_geom::{ClosedForm, Pellet, Resolution, ShapeSpec, Tube};

use crate::trajectory::Frame;

/// Topic of the scene entities.
pub const SCENE_TOPIC: &str = "/foxglove/scene";
/// Topic of the per-frame transforms.
pub const TRANSFORMS_TOPIC: &str = "/foxglove/transforms";
/// Foxglove's schema name of a scene update.
pub const SCENE_SCHEMA: &str = "foxglove.SceneUpdate";
/// Foxglove's schema name of a list of transforms.
pub const TRANSFORMS_SCHEMA: &str = "foxglove.FrameTransforms";
/// Message encoding of the viewer channels.
pub const VIEWER_MESSAGE_ENCODING: &str = "json";
/// Schema encoding of the viewer channels.
pub const VIEWER_SCHEMA_ENCODING: &str = "jsonschema";
/// The fixed frame.
pub const WORLD_FRAME: &str = "world";

/// How one pellet type is drawn, in its body frame (m).
#[derive(Clone, Debug, PartialEq)]
pub enum ViewerShape {
    /// A sphere of this diameter.
    Sphere {
        /// Diameter (m).
        diameter: f64,
    },
    /// A cylinder along body z.
    Cylinder {
        /// Diameter (m).
        diameter: f64,
        /// Height (m).
        height: f64,
    },
    /// An indexed triangle list.
    Triangles {
        /// Vertices (m).
        points: Vec<[f64; 3]>,
        /// Three vertex indices per triangle, counter-clockwise seen from outside.
        indices: Vec<u32>,
    },
}

impl ViewerShape {
    /// The drawing of a pellet type: exact primitives where Foxglove has one,
    /// else the level-0 control mesh of catalogue shapes (a user mesh as is).
    pub fn of(pellet: &Pellet) -> ViewerShape {
        match pellet.closed_form {
            Some(ClosedForm::Sphere { radius }) => return ViewerShape::Sphere { diameter: 2.0 * radius },
            Some(ClosedForm::Cylinder { radius, half_height }) => {
                return ViewerShape::Cylinder { diameter: 2.0 * radius, height: 2.0 * half_height }
            }
            _ => {}
        }
        let coarse = match pellet.shape {
            ShapeSpec::UserMesh { .. } => None,
            _ => Pellet::build(pellet.shape.clone(), Resolution { level: 0, faces: None }).ok(),
        };
        let mesh = coarse.as_ref().map_or(&pellet.mesh, |p| &p.mesh);
        ViewerShape::Triangles {
            points: mesh.vertices.iter().map(|v| [v.x, v.y, v.z]).collect(),
            indices: mesh.triangles.iter().flatten().copied().collect(),
        }
    }
}

/// Frame id of pellet `i`.
pub fn pellet_frame(i: usize) -> String {
    format!("pellet-{i}")
}

fn time(time_s: f64) -> Value {
    let ns = (time_s.max(0.0) * 1e9).round() as u64;
    json!({ "sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000 })
}

fn identity_pose(z: f64) -> Value {
    json!({ "position": { "x": 0.0, "y": 0.0, "z": z }, "orientation": { "x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0 } })
}

fn color(rgba: [f64; 4]) -> Value {
    json!({ "r": rgba[0], "g": rgba[1], "b": rgba[2], "a": rgba[3] })
}

/// A scene entity with every primitive list present (viewers index them all).
fn entity(time_s: f64, frame_id: &str, id: &str, kind: &str, primitives: (&str, Value)) -> Value {
    let mut e = json!({
        "timestamp": time(time_s),
        "frame_id": frame_id,
        "id": id,
        "lifetime": { "sec": 0, "nsec": 0 },
        "frame_locked": true,
        "metadata": [{ "key": "kind", "value": kind }],
        "arrows": [], "cubes": [], "spheres": [], "cylinders": [],
        "lines": [], "triangles": [], "texts": [], "models": []
    });
    e[primitives.0] = primitives.1;
    e
}

const PELLET_COLOR: [f64; 4] = [0.85, 0.55, 0.25, 1.0];

/// The entity drawing pellet `i` in its own frame.
pub fn pellet_entity(time_s: f64, i: usize, shape: &ViewerShape) -> Value {
    let frame = pellet_frame(i);
    let primitives = match shape {
        ViewerShape::Sphere { diameter } => (
            "spheres",
            json!([{ "pose": identity_pose(0.0), "size": { "x": diameter, "y": diameter, "z": diameter },
                     "color": color(PELLET_COLOR) }]),
        ),
        ViewerShape::Cylinder { diameter, height } => (
            "cylinders",
            json!([{ "pose": identity_pose(0.0), "size": { "x": diameter, "y": diameter, "z": height },
                     "bottom_scale": 1.0, "top_scale": 1.0, "color": color(PELLET_COLOR) }]),
        ),
        ViewerShape::Triangles { points, indices } => {
            let points: Vec<Value> = points.iter().map(|p| json!({ "x": p[0], "y": p[1], "z": p[2] })).collect();
            (
                "triangles",
                json!([{ "pose": identity_pose(0.0), "points": points, "color": color(PELLET_COLOR),
                         "colors": [], "indices": indices }]),
            )
        }
    };
    entity(time_s, &frame, &frame, "pellet", primitives)
}

/// The tube drawn as a translucent cylinder from the floor to `height_m`.
pub fn tube_entity(tube: &Tube, height_m: f64) -> Value {
    let d = tube.diameter;
    let primitives = (
        "cylinders",
        json!([{ "pose": identity_pose(0.5 * height_m), "size": { "x": d, "y": d, "z": height_m },
                 "bottom_scale": 1.0, "top_scale": 1.0, "color": color([0.6, 0.75, 0.9, 0.15]) }]),
    );
    entity(0.0, WORLD_FRAME, "tube", "tube", primitives)
}

/// A `foxglove.SceneUpdate` adding `entities`.
pub fn scene_update(entities: Vec<Value>) -> Value {
    json!({ "deletions": [], "entities": entities })
}

/// A `foxglove.FrameTransforms` placing every pellet of `frame` in `world`.
pub fn frame_transforms(frame: &Frame) -> Value {
    let stamp = time(frame.time_s);
    let transforms: Vec<Value> = frame
        .positions
        .iter()
        .zip(&frame.orientations)
        .enumerate()
        .map(|(i, (p, q))| {
            json!({
                "timestamp": stamp,
                "parent_frame_id": WORLD_FRAME,
                "child_frame_id": pellet_frame(i),
                "translation": { "x": p[0], "y": p[1], "z": p[2] },
                "rotation": { "x": q[1], "y": q[2], "z": q[3], "w": q[0] }
            })
        })
        .collect();
    json!({ "transforms": transforms })
}

fn object(title: &str, properties: Value) -> Value {
    json!({ "title": title, "type": "object", "properties": properties })
}

fn array(items: Value) -> Value {
    json!({ "type": "array", "items": items })
}

fn numbers(names: &[&str]) -> Value {
    Value::Object(names.iter().map(|n| (n.to_string(), json!({ "type": "number" }))).collect())
}

fn time_schema() -> Value {
    json!({ "type": "object", "title": "time",
            "properties": { "sec": { "type": "integer", "minimum": 0 }, "nsec": { "type": "integer", "minimum": 0 } } })
}

fn vector3(title: &str) -> Value {
    object(title, numbers(&["x", "y", "z"]))
}

fn quaternion() -> Value {
    object("foxglove.Quaternion", numbers(&["x", "y", "z", "w"]))
}

fn pose() -> Value {
    object("foxglove.Pose", json!({ "position": vector3("foxglove.Vector3"), "orientation": quaternion() }))
}

fn color_schema() -> Value {
    object("foxglove.Color", numbers(&["r", "g", "b", "a"]))
}

/// JSON schema of the `foxglove.SceneUpdate` messages written here.
pub fn scene_schema() -> Value {
    let sized = |title: &str, extra: Value| {
        let mut props = json!({ "pose": pose(), "size": vector3("foxglove.Vector3"), "color": color_schema() });
        if let (Some(p), Some(e)) = (props.as_object_mut(), extra.as_object()) {
            p.extend(e.clone());
        }
        object(title, props)
    };
    let triangles = object(
        "foxglove.TriangleListPrimitive",
        json!({ "pose": pose(), "points": array(vector3("foxglove.Point3")), "color": color_schema(),
                "colors": array(color_schema()), "indices": array(json!({ "type": "integer", "minimum": 0 })) }),
    );
    let entity = object(
        "foxglove.SceneEntity",
        json!({
            "timestamp": time_schema(), "frame_id": { "type": "string" }, "id": { "type": "string" },
            "lifetime": time_schema(), "frame_locked": { "type": "boolean" },
            "metadata": array(object("foxglove.KeyValuePair",
                json!({ "key": { "type": "string" }, "value": { "type": "string" } }))),
            "spheres": array(sized("foxglove.SpherePrimitive", json!({}))),
            "cylinders": array(sized("foxglove.CylinderPrimitive",
                json!({ "bottom_scale": { "type": "number" }, "top_scale": { "type": "number" } }))),
            "triangles": array(triangles),
            "arrows": array(json!({ "type": "object" })), "cubes": array(json!({ "type": "object" })),
            "lines": array(json!({ "type": "object" })), "texts": array(json!({ "type": "object" })),
            "models": array(json!({ "type": "object" }))
        }),
    );
    let deletion = object(
        "foxglove.SceneEntityDeletion",
        json!({ "timestamp": time_schema(), "type": { "type": "integer" }, "id": { "type": "string" } }),
    );
    object(SCENE_SCHEMA, json!({ "deletions": array(deletion), "entities": array(entity) }))
}

/// JSON schema of the `foxglove.FrameTransforms` messages written here.
pub fn transforms_schema() -> Value {
    let transform = object(
        "foxglove.FrameTransform",
        json!({ "timestamp": time_schema(), "parent_frame_id": { "type": "string" },
                "child_frame_id": { "type": "string" }, "translation": vector3("foxglove.Vector3"),
                "rotation": quaternion() }),
    );
    object(TRANSFORMS_SCHEMA, json!({ "transforms": array(transform) }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transforms_swap_the_quaternion_to_xyzw_and_keep_metres() {
        let frame = Frame {
            time_s: 1.25,
            type_index: vec![0],
            positions: vec![[0.001, -0.002, 0.003]],
            orientations: vec![[0.5, 0.5, -0.5, 0.5]],
            velocities: None,
        };
        let t = &frame_transforms(&frame)["transforms"][0];
        assert_eq!(t["child_frame_id"], "pellet-0");
        assert_eq!(t["rotation"]["w"], 0.5);
        assert_eq!(t["rotation"]["y"], -0.5);
        assert_eq!(t["translation"]["z"], 0.003);
        assert_eq!(t["timestamp"]["sec"], 1);
        assert_eq!(t["timestamp"]["nsec"], 250_000_000);
    }

    #[test]
    fn rings_are_drawn_with_their_coarse_mesh_and_valid_indices() {
        let spec = ShapeSpec::Ring { outer_diameter_mm: 10.0, inner_diameter_mm: 6.0, height_mm: 10.0 };
        let ring = Pellet::build(spec, Resolution::default()).unwrap();
        let ViewerShape::Triangles { points, indices } = ViewerShape::of(&ring) else {
            panic!("ring drawn as primitive")
        };
        assert_eq!(indices.len() % 3, 0);
        assert!(indices.len() / 3 < ring.mesh.triangles.len() / 4, "viewer mesh should be coarse");
        assert!(indices.iter().all(|&i| (i as usize) < points.len()));
    }
}
