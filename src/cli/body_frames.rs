//! `drape body-frames`: a scene's deforming mesh obstacle (an articulated
//! body with `surface = "skinned_mesh"`) written as one OBJ file per
//! recorded frame, which a `mesh_sequence` obstacle reads back.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::Args;

use crate::emit;
use drape::collide::{Drawn, Obstacles};
use drape::kinematics::skin::obj_text;
use drape::math::Vector;
use drape::scene::load_scene_file;

/// The arguments of `drape body-frames`.
#[derive(Args)]
pub struct BodyFramesArgs {
    /// Scene file (TOML) with a deforming mesh obstacle.
    scene: PathBuf,
    /// Directory for `frame_0000.obj`, `frame_0001.obj`, ... (created if missing).
    dir: PathBuf,
    /// Override a scene value by its dotted path, e.g. `--set obstacle.0.surface=skinned_mesh` (repeatable).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    overrides: Vec<String>,
}

/// Writes the first deforming mesh obstacle of the scene at every recorded
/// frame time (`simulation.frame_rate` over `simulation.duration`).
pub fn cmd_body_frames(args: BodyFramesArgs) -> Result<ExitCode> {
    let scene = load_scene_file(&args.scene, &args.overrides)?;
    let obstacles = Obstacles::from_scene(&scene)?;
    let rate = scene.simulation.frame_rate;
    let frames = (scene.simulation.duration * rate).round() as u64;
    std::fs::create_dir_all(&args.dir)
        .with_context(|| format!("cannot create the directory {}", args.dir.display()))?;
    let mut triangles = Vec::new();
    for k in 0..=frames {
        let t = k as f64 / rate;
        let Some(mesh) = obstacles
            .meshes(t, (Vector::ZERO, 1.0), true)
            .into_iter()
            .find(|m| m.drawn == Drawn::Deforming)
        else {
            bail!(
                "{}: the scene has no deforming mesh obstacle: give an articulated obstacle `surface = \"skinned_mesh\"` (e.g. --set obstacle.0.surface=skinned_mesh)",
                args.scene.display()
            );
        };
        triangles = mesh.triangles.clone();
        let path = args.dir.join(format!("frame_{k:04}.obj"));
        std::fs::write(&path, obj_text(&mesh.positions, &mesh.triangles))
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    emit(&format!(
        "wrote {} frames of {} triangles at {rate} frames/s to {}/frame_0000.obj ... frame_{frames:04}.obj\n",
        frames + 1,
        triangles.len(),
        args.dir.display()
    ))?;
    Ok(ExitCode::SUCCESS)
}
