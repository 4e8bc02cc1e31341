//! `mkpellet`: makes a pellet file (mesh, mass properties, collision
//! geometry) for a catalogue shape or a user's mesh, and prints what a
//! pellet file holds.

use anyhow::{bail, Context};
use clap::{Args as ClapArgs, Parser, Subcommand, ValueEnum};

use pellet_cli::{positive_mm, Outcome};
use pellet_geom::{Pellet, Resolution, ShapeSpec};
use pellet_io::{OutputFile, PelletFile, Provenance};

mod info;

const EXAMPLES: &str = "\
Examples:
  mkpellet sphere --diameter 10 -o s.pellet
  mkpellet cylinder --diameter 10 --height 10 -o c.pellet --stl c.stl
  mkpellet ring --outer-diameter 10 --inner-diameter 6 --height 10 -o r.pellet
  mkpellet ring --outer-diameter 10 --wall 2 --height 10 -o r.pellet --faces 20000
  mkpellet trilobe --lobe-diameter 1.6 --size 2.9 --height 5 -o tl.pellet
  mkpellet multihole --diameter 16 --height 16 --holes 7 --center-hole --hole-diameter 2.8 --pitch-diameter 9 -o 7h.pellet
  mkpellet import part.stl --unit mm -o part.pellet
  mkpellet info c.pellet            (or: mkpellet info c.pellet --json | jq .volume_mm3)

All lengths are in millimetres. Exit codes: 0 success, 2 error.";

/// Make catalyst pellet files: a closed Loop-subdivided triangle mesh with
/// exact mass properties and collision geometry, for `pack`.
#[derive(Debug, Parser)]
#[command(name = "mkpellet", version = pellet_cli::LONG_VERSION, after_help = EXAMPLES)]
pub struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// A sphere.
    #[command(allow_negative_numbers = true, after_help = "Example: mkpellet sphere --diameter 10 -o s.pellet")]
    Sphere {
        /// Diameter (mm).
        #[arg(long)]
        diameter: f64,
        #[command(flatten)]
        out: MeshOutput,
    },
    /// A solid cylinder (axis along body z).
    #[command(
        allow_negative_numbers = true,
        after_help = "Example: mkpellet cylinder --diameter 10 --height 10 -o c.pellet --stl c.stl"
    )]
    Cylinder {
        /// Diameter (mm).
        #[arg(long)]
        diameter: f64,
        /// Height (mm).
        #[arg(long)]
        height: f64,
        #[command(flatten)]
        out: MeshOutput,
    },
    /// A Raschig ring (hollow cylinder); give --inner-diameter or --wall.
    #[command(
        allow_negative_numbers = true,
        after_help = "Example: mkpellet ring --outer-diameter 10 --inner-diameter 6 --height 10 -o r.pellet"
    )]
    Ring {
        /// Outer diameter (mm).
        #[arg(long)]
        outer_diameter: f64,
        /// Inner (hole) diameter (mm).
        #[arg(long, required_unless_present = "wall", conflicts_with = "wall")]
        inner_diameter: Option<f64>,
        /// Wall thickness (mm), instead of --inner-diameter.
        #[arg(long)]
        wall: Option<f64>,
        /// Height (mm).
        #[arg(long)]
        height: f64,
        #[command(flatten)]
        out: MeshOutput,
    },
    /// A trilobe extrudate: three overlapping lobes.
    #[command(
        allow_negative_numbers = true,
        after_help = "Example: mkpellet trilobe --lobe-diameter 1.6 --size 2.9 --height 5 -o tl.pellet"
    )]
    Trilobe {
        #[command(flatten)]
        lobes: LobeArgs,
        #[command(flatten)]
        out: MeshOutput,
    },
    /// A quadrilobe extrudate: four overlapping lobes.
    #[command(
        allow_negative_numbers = true,
        after_help = "Example: mkpellet quadrilobe --lobe-diameter 1.5 --size 2.8 --height 5 -o ql.pellet"
    )]
    Quadrilobe {
        #[command(flatten)]
        lobes: LobeArgs,
        #[command(flatten)]
        out: MeshOutput,
    },
    /// A multi-hole cylinder (e.g. 4-hole, or 7-hole with --center-hole).
    #[command(
        allow_negative_numbers = true,
        after_help = "Examples:\n  mkpellet multihole --diameter 16 --height 16 --holes 4 --hole-diameter 4 --pitch-diameter 8 -o 4h.pellet\n  mkpellet multihole --diameter 16 --height 10 --holes 7 --center-hole --hole-diameter 2.8 --pitch-diameter 9 -o 7h.pellet"
    )]
    Multihole {
        /// Outer diameter (mm).
        #[arg(long)]
        diameter: f64,
        /// Height (mm).
        #[arg(long)]
        height: f64,
        /// Total number of holes (1–64).
        #[arg(long)]
        holes: u32,
        /// Put one of the holes on the axis (the rest go on the pitch circle).
        #[arg(long)]
        center_hole: bool,
        /// Diameter of each hole (mm).
        #[arg(long)]
        hole_diameter: f64,
        /// Diameter of the circle through the off-axis hole centres (mm).
        #[arg(long)]
        pitch_diameter: f64,
        #[command(flatten)]
        out: MeshOutput,
    },
    /// A pellet from your own closed mesh (binary/ASCII STL or OBJ).
    #[command(after_help = "Example: mkpellet import part.stl --unit mm -o part.pellet")]
    Import {
        /// The mesh file (.stl or .obj); `-` reads STL from stdin.
        input: String,
        /// Length unit of the mesh file.
        #[arg(long, value_enum, default_value_t = Unit::Mm)]
        unit: Unit,
        /// Pellet file to write (`-` = stdout, not a terminal).
        #[arg(short, long, default_value = "-")]
        output: String,
        /// Also write the (re-centred) mesh as binary STL in mm.
        #[arg(long)]
        stl: Option<String>,
        /// Also write the mesh as OBJ in mm.
        #[arg(long)]
        obj: Option<String>,
    },
    /// Print what a pellet file holds: shape, mesh, properties, collision pieces.
    #[command(allow_negative_numbers = true, after_help = "Example: mkpellet info c.pellet --density 2500")]
    Info {
        /// The pellet file (`-` = stdin).
        #[arg(default_value = "-")]
        input: String,
        /// Print JSON (SI and mm fields, units in the key names) instead of text.
        #[arg(long)]
        json: bool,
        /// Density for the mass and inertia lines (kg/m³).
        #[arg(long, default_value_t = 8030.0)]
        density: f64,
        /// Also write the mesh as binary STL in mm.
        #[arg(long)]
        stl: Option<String>,
        /// Also write the mesh as OBJ in mm.
        #[arg(long)]
        obj: Option<String>,
    },
}

#[derive(Debug, ClapArgs)]
struct LobeArgs {
    /// Diameter of each lobe (mm).
    #[arg(long)]
    lobe_diameter: f64,
    /// Overall size: diameter of the circle around the lobes (mm).
    #[arg(long)]
    size: f64,
    /// Height (mm).
    #[arg(long)]
    height: f64,
}

#[derive(Debug, ClapArgs)]
struct MeshOutput {
    /// Pellet file to write (`-` = stdout, not a terminal).
    #[arg(short, long, default_value = "-")]
    output: String,
    /// Also write the mesh as binary STL in mm (for ParaView, Blender, CFD meshers).
    #[arg(long)]
    stl: Option<String>,
    /// Also write the mesh as OBJ in mm.
    #[arg(long)]
    obj: Option<String>,
    /// Loop subdivision levels (0–6; each multiplies the faces by 4) [default: 2].
    #[arg(long)]
    level: Option<u32>,
    /// Target face count (the control mesh is chosen to come closest)
    /// [default: sphere 4400, cylinder 4400, ring 8008, lobes 6000, multihole 6000 + 2000 per hole].
    #[arg(long)]
    faces: Option<usize>,
}

/// Length units of user mesh files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Unit {
    /// Millimetres.
    Mm,
    /// Metres.
    M,
    /// Inches.
    In,
}

impl Unit {
    fn to_metres(self) -> f64 {
        match self {
            Unit::Mm => 1e-3,
            Unit::M => 1.0,
            Unit::In => 0.0254,
        }
    }
}

/// Runs `mkpellet`.
pub fn run(args: Args) -> anyhow::Result<Outcome> {
    let (shape, out) = match args.command {
        Command::Info { input, json, density, stl, obj } => {
            pellet_cli::refuse_clashing_outputs([&input], mesh_flags(stl.as_deref(), obj.as_deref()))?;
            return info::run(&input, json, density, stl.as_deref(), obj.as_deref());
        }
        Command::Import { input, unit, output, stl, obj } => {
            let outputs = std::iter::once(("-o".to_string(), output.clone()));
            pellet_cli::refuse_clashing_outputs([&input], outputs.chain(mesh_flags(stl.as_deref(), obj.as_deref())))?;
            let pellet = import(&input, unit)?;
            write_pellet(&pellet, &output, stl.as_deref(), obj.as_deref())?;
            return Ok(Outcome::Success);
        }
        Command::Sphere { diameter, out } => (ShapeSpec::Sphere { diameter_mm: diameter }, out),
        Command::Cylinder { diameter, height, out } => {
            (ShapeSpec::Cylinder { diameter_mm: diameter, height_mm: height }, out)
        }
        Command::Ring { outer_diameter, inner_diameter, wall, height, out } => {
            let inner = match (inner_diameter, wall) {
                (Some(d), _) => d,
                (None, Some(w)) => {
                    positive_mm("--outer-diameter", outer_diameter)?;
                    positive_mm("--wall", w)?;
                    if 2.0 * w >= outer_diameter {
                        bail!(
                            "--wall must be less than half of --outer-diameter, i.e. < {} mm (got {w} mm)",
                            0.5 * outer_diameter
                        );
                    }
                    outer_diameter - 2.0 * w
                }
                (None, None) => bail!("give --inner-diameter or --wall"),
            };
            (ShapeSpec::Ring { outer_diameter_mm: outer_diameter, inner_diameter_mm: inner, height_mm: height }, out)
        }
        Command::Trilobe { lobes, out } => (lobed(3, lobes), out),
        Command::Quadrilobe { lobes, out } => (lobed(4, lobes), out),
        Command::Multihole { diameter, height, holes, center_hole, hole_diameter, pitch_diameter, out } => (
            ShapeSpec::MultiHole {
                diameter_mm: diameter,
                height_mm: height,
                holes,
                center_hole,
                hole_diameter_mm: hole_diameter,
                pitch_diameter_mm: pitch_diameter,
            },
            out,
        ),
    };
    let outputs = std::iter::once(("-o".to_string(), out.output.clone()));
    pellet_cli::refuse_clashing_outputs(
        [] as [&str; 0],
        outputs.chain(mesh_flags(out.stl.as_deref(), out.obj.as_deref())),
    )?;
    let resolution = Resolution { level: out.level.unwrap_or(Resolution::DEFAULT_LEVEL), faces: out.faces };
    let pellet = Pellet::build(shape, resolution)?;
    write_pellet(&pellet, &out.output, out.stl.as_deref(), out.obj.as_deref())?;
    Ok(Outcome::Success)
}

fn lobed(lobes: u32, a: LobeArgs) -> ShapeSpec {
    ShapeSpec::Lobed { lobes, lobe_diameter_mm: a.lobe_diameter, size_mm: a.size, height_mm: a.height }
}

fn import(input: &str, unit: Unit) -> anyhow::Result<Pellet> {
    let format = if input == "-" {
        pellet_io::MeshFormat::Stl
    } else {
        pellet_io::MeshFormat::from_path(input)
            .with_context(|| format!("{input}: unknown mesh format; use a .stl or .obj file"))?
    };
    let bytes = pellet_io::read_input(input)?;
    let mut mesh = pellet_io::read_mesh(&bytes, format, input)?;
    mesh.scale(unit.to_metres());
    let unit_name = format!("{unit:?}").to_lowercase();
    Pellet::from_mesh(mesh, input.to_string(), unit_name).with_context(|| input.to_string())
}

/// The pellet file bytes for `pellet`, stamped with this run's command line.
pub fn pellet_bytes(pellet: &Pellet) -> anyhow::Result<Vec<u8>> {
    let file = PelletFile {
        length_unit: "m".into(),
        provenance: Provenance {
            tool: "mkpellet".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            args: std::env::args().skip(1).collect(),
        },
        pellet: pellet.clone(),
    };
    Ok(pellet_io::encode_pellet(&file)?)
}

fn write_pellet(pellet: &Pellet, output: &str, stl: Option<&str>, obj: Option<&str>) -> anyhow::Result<()> {
    let mut outputs = vec![OutputFile {
        path: output.into(),
        bytes: pellet_bytes(pellet)?,
        binary: true,
        what: "pellet file".into(),
    }];
    outputs.extend(mesh_exports(pellet, stl, obj)?);
    pellet_io::write_outputs(&outputs)?;
    for note in &pellet.notes {
        eprintln!("mkpellet: note: {note}");
    }
    Ok(())
}

fn mesh_flags(stl: Option<&str>, obj: Option<&str>) -> Vec<(String, String)> {
    [("--stl", stl), ("--obj", obj)].into_iter().filter_map(|(f, p)| Some((f.to_string(), p?.to_string()))).collect()
}

/// The `--stl` / `--obj` exports of a pellet's mesh, in millimetres.
pub(crate) fn mesh_exports(pellet: &Pellet, stl: Option<&str>, obj: Option<&str>) -> anyhow::Result<Vec<OutputFile>> {
    let mut outputs = Vec::new();
    if let Some(path) = stl {
        let bytes = pellet_io::stl_bytes(&pellet.mesh, 1e3)?;
        outputs.push(OutputFile { path: path.into(), bytes, binary: true, what: "STL".into() });
    }
    if let Some(path) = obj {
        let comment = format!("packbed {} pellet, body frame, millimetres", pellet.shape.kind());
        let bytes = pellet_io::obj_bytes(&pellet.mesh, 1e3, &comment);
        outputs.push(OutputFile { path: path.into(), bytes, binary: false, what: "OBJ".into() });
    }
    Ok(outputs)
}
