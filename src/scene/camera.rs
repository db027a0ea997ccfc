//! `[camera]`: where the recording's 3D views look from. The table is read as written and
//! resolved into the recorder's [`Camera`] once validated: a named side, or an eye and the
//! point it looks at.

use serde::Deserialize;

use crate::math::Vector;
use crate::record::{Camera, CameraSide};

use super::error::{Issue, SceneErrorKind as Kind, keys};
use super::validate::all_finite;

/// `[camera]` as written: either `side`, or `eye` with `look_at`.
#[derive(Debug, Clone, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CameraTable {
    /// A named side to look from (`front`, `back`, `left`, `right`, `top`).
    pub side: Option<CameraSide>,
    /// The eye's position, m.
    pub eye: Option<[f64; 3]>,
    /// The point the eye looks at, m (with `eye`).
    pub look_at: Option<[f64; 3]>,
}

impl CameraTable {
    /// The camera the table asks for (call after [`validate`]: an eye without a point to
    /// look at is refused there).
    pub fn camera(&self) -> Camera {
        match (self.side, self.eye, self.look_at) {
            (Some(side), ..) => Camera::Side(side),
            (None, Some(eye), Some(look_at)) => Camera::At {
                eye: Vector::from_array(eye),
                look_at: Vector::from_array(look_at),
            },
            _ => Camera::Follow,
        }
    }
}

/// Checks that the table names a side or an eye with a distinct, finite look-at point, not
/// both.
pub(super) fn validate(camera: &CameraTable) -> Result<(), Issue> {
    let at = |k: &str| keys(&["camera", k]);
    match (camera.side, camera.eye, camera.look_at) {
        (Some(_), None, None) => Ok(()),
        (Some(_), Some(_), _) | (Some(_), None, Some(_)) => {
            let k = if camera.eye.is_some() {
                "eye"
            } else {
                "look_at"
            };
            Err(Issue::new(
                at(k),
                Kind::NotApplicable,
                "give either `side` or `eye` with `look_at`, not both",
            )
            .because(at("side")))
        }
        (None, None, None) => Err(Issue::new(
            at("side"),
            Kind::MissingKey,
            "[camera] needs `side`, or `eye` with `look_at`",
        )
        .allowed("\"front\", \"back\", \"left\", \"right\", \"top\"")),
        (None, Some(_), None) | (None, None, Some(_)) => {
            let missing = if camera.eye.is_some() {
                "look_at"
            } else {
                "eye"
            };
            Err(Issue::new(
                at(missing),
                Kind::MissingKey,
                format!("missing required key `{missing}`: `eye` and `look_at` go together"),
            ))
        }
        (None, Some(eye), Some(look_at)) => {
            all_finite(at("eye"), &eye)?;
            all_finite(at("look_at"), &look_at)?;
            if eye == look_at {
                return Err(Issue::new(
                    at("look_at"),
                    Kind::BadValue,
                    "the eye looks at itself: `look_at` must differ from `eye`",
                ));
            }
            Ok(())
        }
    }
}
