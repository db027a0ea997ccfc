//! The obstacles of a run in its recording: meshes at `obstacles/<name>`, static or per
//! frame, and the poses of moving rigid ones.

use super::{ENTITY_OBSTACLES, RecordError, Recorder, convert};
use crate::math::Vector;

/// Colour of the obstacles (light grey).
const OBSTACLE_COLOR: [u8; 3] = [0xB0, 0xB0, 0xB0];

impl Recorder {
    /// Logs an obstacle's triangulation at `obstacles/<name>` (non-alphanumeric characters of
    /// `name` become `_`) in a neutral grey: as static data when `fixed` (log it once), else
    /// at the current frame (call it after [`Recorder::record_frame`] every frame).
    pub fn record_obstacle(
        &mut self,
        name: &str,
        positions: &[Vector],
        triangles: &[[u32; 3]],
        fixed: bool,
    ) -> Result<(), RecordError> {
        check_indices(name, positions, triangles)?;
        let entity = obstacle_entity(name);
        let [r, g, b] = OBSTACLE_COLOR;
        let mesh = rerun::Mesh3D::new(positions.iter().map(|&p| convert::position(p)))
            .with_triangle_indices(triangles.iter().copied())
            .with_albedo_factor(rerun::Rgba32::from_rgb(r, g, b));
        let logged = if fixed {
            self.stream().log_static(entity.as_str(), &mesh)
        } else {
            self.stream().log(entity.as_str(), &mesh)
        };
        logged.map_err(|e| self.log_err(&entity, e))
    }

    /// Logs a deforming obstacle mesh at `obstacles/<name>`: its vertex
    /// positions at the current frame and, when `triangles` is not empty (the
    /// first frame), its triangles and colour as static data, which every
    /// frame's positions share (call it after [`Recorder::record_frame`]
    /// every frame).
    pub fn record_deforming_obstacle(
        &mut self,
        name: &str,
        positions: &[Vector],
        triangles: &[[u32; 3]],
    ) -> Result<(), RecordError> {
        check_indices(name, positions, triangles)?;
        let entity = obstacle_entity(name);
        if !triangles.is_empty() {
            let [r, g, b] = OBSTACLE_COLOR;
            let topology = rerun::Mesh3D::update_fields()
                .with_triangle_indices(triangles.iter().copied())
                .with_albedo_factor(rerun::Rgba32::from_rgb(r, g, b));
            self.stream()
                .log_static(entity.as_str(), &topology)
                .map_err(|e| self.log_err(&entity, e))?;
        }
        let moved = rerun::Mesh3D::update_fields()
            .with_vertex_positions(positions.iter().map(|&p| convert::position(p)));
        self.stream()
            .log(entity.as_str(), &moved)
            .map_err(|e| self.log_err(&entity, e))
    }

    /// Logs a moving rigid obstacle's pose at the current frame as the
    /// `Transform3D` of `obstacles/<name>`, which places the mesh that
    /// [`Recorder::record_obstacle`] logged once in the obstacle's local frame
    /// (call it after [`Recorder::record_frame`] every frame).
    pub fn record_obstacle_pose(
        &mut self,
        name: &str,
        translation: Vector,
        rotation: glam::DQuat,
    ) -> Result<(), RecordError> {
        let entity = obstacle_entity(name);
        let q = rotation.normalize().to_array().map(|c| c as f32);
        let transform = rerun::Transform3D::from_translation_rotation(
            convert::f32x3(translation),
            rerun::Quaternion::from_xyzw(q),
        );
        self.stream()
            .log(entity.as_str(), &transform)
            .map_err(|e| self.log_err(&entity, e))
    }
}

/// `obstacles/<name>`, the characters of `name` other than ASCII letters and
/// digits replaced by `_`.
fn obstacle_entity(name: &str) -> String {
    let clean: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    format!("{ENTITY_OBSTACLES}/{clean}")
}

/// Refuses an obstacle mesh whose triangles index past its vertices.
fn check_indices(
    name: &str,
    positions: &[Vector],
    triangles: &[[u32; 3]],
) -> Result<(), RecordError> {
    let n = positions.len();
    match triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        Some(t) => Err(RecordError::InvalidFrame {
            frame: 0,
            reason: format!("obstacle {name}: triangle {t:?} indexes past {n} vertices"),
        }),
        None => Ok(()),
    }
}
