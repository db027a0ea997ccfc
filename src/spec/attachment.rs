//! Attachments: panel sides of a garment held on one side of a plane for a
//! while, as GarmentCode holds a pattern's labelled edges at the body
//! (`[[attachment]]`, [scenes.md](../../docs/scenes.md)).
//!
//! The sides an attachment names are part of the garment (the mesh keeps
//! which vertices lie on them, `mesh::Hold`); its plane, stiffness and release
//! time are part of the physics model (`physics::Model::attachments`).

use serde::Deserialize;

use super::SeamSide;
use crate::math::{Scalar, Vector};

/// The stiffness an attachment gets unless told otherwise, N/m per m of held
/// side: GarmentCode's `attachment_stiffness`, 1000.
pub const DEFAULT_ATTACHMENT_STIFFNESS: Scalar = 1000.0;

/// `[[attachment]]`: panel sides kept on the side of a plane its normal
/// points to, until a release time.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttachmentTable {
    /// The attachment's name (unique).
    pub name: String,
    /// The held panel sides: `[{ panel = "front", side = 2 }, ...]`.
    pub sides: Vec<SeamSide>,
    /// A point of the plane, in the world, m.
    pub point: [f64; 3],
    /// The plane's normal, in the world (any length > 0): a held vertex is
    /// pulled back when it lies on the other side.
    pub normal: [f64; 3],
    /// Stiffness per metre of held side, N/m per m (> 0).
    #[serde(default = "default_stiffness")]
    pub stiffness: f64,
    /// When the sides are let go, s (>= 0); absent: never.
    pub release: Option<f64>,
}

fn default_stiffness() -> f64 {
    DEFAULT_ATTACHMENT_STIFFNESS
}

/// Which panel sides an attachment holds: the garment's part of it.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldSpec {
    /// The attachment's name.
    pub name: String,
    /// The held panel sides.
    pub sides: Vec<SeamSide>,
}

/// An attachment's pull: the physics model's part of it, one per
/// [`HoldSpec`] of the garment, in the same order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attachment {
    /// A point of the plane, m.
    pub point: Vector,
    /// The plane's unit normal: a held vertex at `x` with
    /// `normal . (x - point) < 0` is pulled back along it.
    pub normal: Vector,
    /// Stiffness per metre of held side, N/m per m: each held vertex gets this
    /// times its share of the held sides' length.
    pub stiffness: Scalar,
    /// When the sides are let go, s (`INFINITY`: never).
    pub release: Scalar,
}

impl Attachment {
    /// True while the attachment holds at time `t`.
    pub fn holds_at(&self, t: Scalar) -> bool {
        t < self.release
    }
}

impl AttachmentTable {
    /// The garment's part: which sides are held.
    pub fn hold(&self) -> HoldSpec {
        HoldSpec {
            name: self.name.clone(),
            sides: self.sides.clone(),
        }
    }

    /// The physics model's part (the normal made unit; validation refuses a
    /// zero one).
    pub fn pull(&self) -> Attachment {
        let n = Vector::from_array(self.normal);
        Attachment {
            point: Vector::from_array(self.point),
            normal: n.normalize_or_zero(),
            stiffness: self.stiffness,
            release: self.release.unwrap_or(Scalar::INFINITY),
        }
    }
}
