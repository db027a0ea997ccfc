//! `drape garment`: a GarmentCode pattern draped on a body. The pattern and
//! the body become a scene (`drape::garmentcode::scene_text`), which
//! `--write-scene` saves and which runs as `drape run` runs a scene file.

use std::path::{Component, Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};
use clap::{Args, ValueEnum};

use crate::cli::run::run_scene;
use crate::{ColourChoice, EdgeChoice, OutputArgs, RunArgs, SceneArgs};
use drape::garmentcode::attach::{self, PatternAttachment};
use drape::garmentcode::body::{BodySize, check_body};
use drape::garmentcode::clearance::Clearance;
use drape::garmentcode::scene_text::{Body, BodyUp, Draping, scene};
use drape::garmentcode::{Labelled, Pattern};
use drape::scene::load_scene_str_in;
use drape::sim::panels_inside;

/// The draping settings the written scene starts from (`docs/garmentcode.md`).
const DRAPING: Draping = Draping {
    max_edge: 0.02,
    duration: 10.0,
    sewing_stiffness: 1000.0,
    weld_gap: 0.02,
    weightless: 1.0,
    rest_speed: 0.05,
    rest_window: 0.5,
};

#[derive(Args)]
pub struct GarmentArgs {
    /// The GarmentCode specification (`*_specification.json`).
    spec: PathBuf,
    #[command(flatten)]
    body: BodyArgs,
    /// Also write the scene that runs to this file (the body's path relative to it).
    #[arg(long, value_name = "FILE.toml")]
    write_scene: Option<PathBuf>,
    /// Override a value of the scene, e.g. `--set cloth.max_edge=0.03` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    overrides: Vec<String>,
    #[command(flatten)]
    output: OutputArgs,
}

/// The body options `drape garment` and `drape garment-plan` share.
#[derive(Args)]
pub struct BodyArgs {
    /// The body to drape on: an OBJ file (GarmentCode's `assets/bodies/*.obj`).
    #[arg(long, value_name = "BODY.obj")]
    pub body: PathBuf,
    /// Which axis of the body file points up: `y` (GarmentCode's bodies, turned
    /// by (x, y, z) -> (x, -z, y)) or `z`.
    #[arg(long, value_enum, value_name = "AXIS", default_value_t = Up::Y)]
    pub body_up: Up,
    /// Metres per unit of the body file: 1 for metres, 0.01 for centimetres.
    #[arg(long, value_name = "SCALE", default_value_t = 1.0)]
    pub body_scale: f64,
    /// GarmentCode's measurements of the body (`assets/bodies/*.yaml`, cm),
    /// which place the planes labelled edges are held at; default: the body's
    /// file with the extension `.yaml`, when there is one.
    #[arg(long, value_name = "BODY.yaml")]
    pub body_measurements: Option<PathBuf>,
    /// Hold no labelled edge at the body (write no `[[attachment]]`), whatever
    /// the measurements.
    #[arg(long, conflicts_with = "body_measurements")]
    pub no_hold: bool,
}

impl BodyArgs {
    /// Checks the scale and the body file (readable, with faces, of a human
    /// size); returns the body's size.
    pub fn check(&self) -> Result<BodySize> {
        if !(self.body_scale.is_finite() && self.body_scale > 0.0) {
            anyhow::bail!("--body-scale must be a number > 0, got {}", self.body_scale);
        }
        Ok(check_body(&self.body, self.body_scale)?)
    }

    /// The measurements file: the one given, or the body's `.yaml` beside it
    /// when there is one.
    pub fn measurements_file(&self) -> Option<PathBuf> {
        let beside = self.body.with_extension("yaml");
        self.body_measurements
            .clone()
            .or_else(|| beside.is_file().then_some(beside))
    }

    /// The attachments of the labelled sides of `pattern` on this body, whose
    /// size is `size` (none with `--no-hold`, and none without a measurements
    /// file, with a note when the pattern has labels GarmentCode holds).
    fn attachments(&self, pattern: &Pattern, size: &BodySize) -> Result<Vec<PatternAttachment>> {
        if self.no_hold {
            return Ok(Vec::new());
        }
        let floor = match self.body_up {
            Up::Y => size.lowest[1],
            Up::Z => size.lowest[2],
        };
        let Some(file) = self.measurements_file() else {
            let held = |l: &&Labelled| attach::HELD_LABELS.contains(&l.label.as_str());
            if pattern.labels.iter().any(|l| held(&l)) {
                eprintln!(
                    "note: no body measurements ({} or --body-measurements): the labelled \
                     edges are not held",
                    self.body.with_extension("yaml").display()
                );
            }
            return Ok(Vec::new());
        };
        let m = attach::load_measurements(&file)?;
        Ok(attach::attachments(&pattern.labels, &m, floor))
    }
}

/// The values of `--body-up`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Up {
    /// y up.
    Y,
    /// z up.
    Z,
}

/// Runs `drape garment`, with `drape run`'s exit codes.
pub fn cmd_garment(args: GarmentArgs) -> Result<ExitCode> {
    let pattern = drape::garmentcode::load(&args.spec)?;
    drape::garmentcode::check(&pattern, DRAPING.max_edge).map_err(|why| {
        drape::garmentcode::GarmentCodeError {
            file: args.spec.display().to_string(),
            why,
        }
    })?;
    let size = args.body.check()?;
    let attachments = args.body.attachments(&pattern, &size)?;
    let name = args
        .spec
        .file_stem()
        .map(|s| {
            s.to_string_lossy()
                .trim_end_matches("_specification")
                .to_owned()
        })
        .filter(|s| !s.is_empty())
        .unwrap_or_else(|| "garment".into());
    let cwd = std::env::current_dir().context("cannot read the current directory")?;
    let scene_dir = match &args.write_scene {
        Some(file) => absolute(&cwd, file.parent().unwrap_or(Path::new(""))),
        None => cwd.clone(),
    };
    let body = Body {
        path: relative(&absolute(&cwd, &args.body.body), &scene_dir),
        up: match args.body.body_up {
            Up::Y => BodyUp::Y,
            Up::Z => BodyUp::Z,
        },
        scale: args.body.body_scale,
    };
    let write = |pattern: &Pattern| {
        scene(
            &name,
            &args.spec.display().to_string(),
            pattern,
            &attachments,
            &body,
            &DRAPING,
        )
    };
    let origin = match &args.write_scene {
        Some(file) => file.display().to_string(),
        None => format!("the scene of {}", args.spec.display()),
    };
    let mut pattern = pattern;
    let mut clearance = Clearance::default();
    let loaded = loop {
        let text = write(&pattern);
        if let Some(file) = &args.write_scene {
            std::fs::write(file, &text)
                .with_context(|| format!("cannot write the scene {}", file.display()))?;
        }
        let loaded = load_scene_str_in(&text, &origin, &scene_dir, &args.overrides)?;
        let inside = panels_inside(&loaded.resolve()?)?;
        if inside.is_empty() {
            break loaded;
        }
        clearance
            .round(&mut pattern, &inside)
            .with_context(|| format!("{}", args.spec.display()))?;
    };
    for m in clearance.moved() {
        eprintln!(
            "{}: panel `{}` starts {:.1} mm inside the body: moved {:.1} mm out along its normal",
            args.spec.display(),
            m.panel,
            1e3 * m.depth,
            1e3 * m.shift.length()
        );
    }
    let run = RunArgs {
        scene: SceneArgs {
            scene: None,
            overrides: args.overrides.clone(),
        },
        output: args.output,
        record_every: 1,
        edges: EdgeChoice::Review,
        no_edges: false,
        edge_threshold: None,
        colour_by: ColourChoice::Panel,
        no_decisions: false,
        spawn: false,
        connect: None,
        sample_at: None,
        samples_out: None,
    };
    run_scene(loaded, &run)
}

/// `path` made absolute against `cwd`, `.` and `..` resolved by name.
fn absolute(cwd: &Path, path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in cwd.join(path).components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// `target` relative to the folder `base` (both absolute), as a string with `/`.
fn relative(target: &Path, base: &Path) -> String {
    let (t, b): (Vec<_>, Vec<_>) = (target.components().collect(), base.components().collect());
    let common = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    if common == 0 {
        return target.display().to_string();
    }
    let mut parts: Vec<String> = vec!["..".into(); b.len() - common];
    parts.extend(
        t[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    parts.join("/")
}
