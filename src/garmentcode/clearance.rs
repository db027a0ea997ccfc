//! Panels that GarmentCode places partly inside the body, moved out of it.
//!
//! GarmentCode's generator places some panels (hoods, the backs of tiered
//! skirts) a centimetre or two inside its bodies; drape refuses a garment
//! that starts inside an obstacle (`sim::build`). `drape garment` therefore
//! moves each such panel, flat as it is, along its own normal, away from the
//! body, until its deepest vertex is [`CLEARANCE`] outside: per round by the
//! depth of that vertex over the cosine between the panel's normal and the
//! body's normal there (at least [`MIN_COSINE`]), then the garment is built
//! again and checked, for at most [`ROUNDS`] rounds and [`MAX_SHIFT`] per
//! panel. The seams of a moved panel start that much wider and are sewn shut
//! as any other.

use std::collections::BTreeMap;

use super::Pattern;
use crate::math::{Scalar, Vector};
use crate::sim::PanelInside;
use crate::spec::Placement;

/// How far outside the body a moved panel's deepest vertex ends up, m.
pub const CLEARANCE: Scalar = 0.005;
/// The smallest cosine a move divides by (a panel meeting the body edge-on
/// moves at most four times its depth per round).
pub const MIN_COSINE: Scalar = 0.25;
/// The furthest one panel is moved in all, m.
pub const MAX_SHIFT: Scalar = 0.15;
/// The most rounds of moving and checking.
pub const ROUNDS: usize = 10;

/// A panel moved out of the body.
#[derive(Debug, Clone, PartialEq)]
pub struct Moved {
    /// The panel.
    pub panel: String,
    /// How deep inside its deepest vertex was as GarmentCode placed it, m.
    pub depth: Scalar,
    /// The whole move, in drape's z-up world, m.
    pub shift: Vector,
}

/// Why the panels could not be moved out of the body.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum ClearanceError {
    /// A panel has no area to take a normal from.
    #[error("panel `{panel}` starts inside the body and has no normal to move it along")]
    NoNormal {
        /// The panel.
        panel: String,
    },
    /// A panel would move further than [`MAX_SHIFT`].
    #[error(
        "panel `{panel}` is {depth_mm:.1} mm inside the body, and moving it out along its \
         normal would take it more than {max_mm:.0} mm from where the pattern places it; place \
         it around the body"
    )]
    TooFar {
        /// The panel.
        panel: String,
        /// How deep inside it is now, mm.
        depth_mm: Scalar,
        /// [`MAX_SHIFT`], mm.
        max_mm: Scalar,
    },
    /// Panels are still inside after [`ROUNDS`] rounds.
    #[error("panel `{panel}` is still {depth_mm:.1} mm inside the body after {rounds} moves")]
    Rounds {
        /// The panel.
        panel: String,
        /// How deep inside it still is, mm.
        depth_mm: Scalar,
        /// [`ROUNDS`].
        rounds: usize,
    },
}

/// The moves made so far, round by round.
#[derive(Debug, Clone, Default)]
pub struct Clearance {
    moved: BTreeMap<String, Moved>,
    rounds: usize,
}

impl Clearance {
    /// One round: moves every panel of `inside` (the garment of `pattern` as
    /// built now, [`crate::sim::panels_inside`]) out along its normal. Fails
    /// when a panel cannot be moved or has moved too far, or after
    /// [`ROUNDS`] rounds.
    pub fn round(
        &mut self,
        pattern: &mut Pattern,
        inside: &[PanelInside],
    ) -> Result<(), ClearanceError> {
        if let Some(p) = inside.first().filter(|_| self.rounds == ROUNDS) {
            return Err(ClearanceError::Rounds {
                panel: p.panel.clone(),
                depth_mm: 1e3 * p.inside.depth,
                rounds: ROUNDS,
            });
        }
        self.rounds += 1;
        for p in inside {
            let shift = shift(p)?;
            let moved = self.moved.entry(p.panel.clone()).or_insert(Moved {
                panel: p.panel.clone(),
                depth: p.inside.depth,
                shift: Vector::ZERO,
            });
            moved.shift += shift;
            if moved.shift.length() > MAX_SHIFT {
                return Err(ClearanceError::TooFar {
                    panel: p.panel.clone(),
                    depth_mm: 1e3 * p.inside.depth,
                    max_mm: 1e3 * MAX_SHIFT,
                });
            }
            pattern.shift_panel(&p.panel, shift);
        }
        Ok(())
    }

    /// The panels moved, by name.
    pub fn moved(&self) -> impl Iterator<Item = &Moved> {
        self.moved.values()
    }
}

/// This round's move of one panel, in the world.
fn shift(p: &PanelInside) -> Result<Vector, ClearanceError> {
    let n = p.panel_normal;
    if n == Vector::ZERO {
        return Err(ClearanceError::NoNormal {
            panel: p.panel.clone(),
        });
    }
    let cosine = n.dot(p.inside.normal);
    let outward = if cosine >= 0.0 { n } else { -n };
    Ok(outward * ((p.inside.depth + CLEARANCE) / cosine.abs().max(MIN_COSINE)))
}

impl Pattern {
    /// Moves panel `name` by `shift`, given in drape's z-up world: the
    /// pattern's frame is GarmentCode's y-up one, turned by (x, y, z) -> (x,
    /// -z, y) (`scene_text.rs`), so the pattern moves by (x, z, -y). Does
    /// nothing for a panel that is not there or not placed flat.
    pub fn shift_panel(&mut self, name: &str, shift: Vector) {
        let by = [shift.x, shift.z, -shift.y];
        for panel in self.panels.iter_mut().filter(|p| p.name == name) {
            if let Placement::Flat { position, .. } = &mut panel.placement {
                for (p, d) in position.iter_mut().zip(by) {
                    *p += d;
                }
            }
        }
    }
}
