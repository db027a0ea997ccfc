//! A garment's phases over a run: it sews weightless (gravity off while a
//! seam is open, for at most `cloth.sewing.weightless` seconds), then drapes
//! under gravity, and the run ends once it is at rest (`simulation.rest`:
//! every seam welded, every attachment with a release time released, and no
//! vertex faster than `speed` over any frame of the last `window` seconds) or
//! at `duration`. A vertex's speed over a frame is
//! how far it moved in the frame over the frame's time: what the frames
//! show, where a velocity at the frame's end may still carry a contact's
//! last correction.

use crate::math::{Scalar, Vector};
use crate::physics::Model;
use crate::scene::Scene;
use crate::spec::Rest;
use crate::summary::RestSummary;
use crate::world::World;

/// The phase a run is in, and the rest criterion's watch.
pub(super) struct Phases {
    /// The scene's gravity.
    gravity: Option<Vector>,
    /// How long the garment may sew weightless, s.
    weightless: Option<Scalar>,
    rest: Option<Rest>,
    /// The last release time of an attachment, s (0 when none has one): the
    /// run is not at rest before it.
    released_by: Scalar,
    /// The start of the current stretch of frames under the rest speed, s.
    calm_since: Option<Scalar>,
    /// When the rest criterion was met, s.
    at_rest: Option<Scalar>,
    /// The largest vertex speed over the last frame, m/s (`None` before the
    /// first frame and after a frame that changed the mesh, as a weld does:
    /// its positions are not comparable with the frame before).
    speed: Option<Scalar>,
    /// Positions at the last frame end and the time then.
    last: (Vec<Vector>, Scalar),
}

impl Phases {
    /// The phases of `scene`, whose model (with the scene's gravity) is
    /// `model`, from the initial state `world`.
    pub(super) fn new(scene: &Scene, model: &Model, world: &World) -> Phases {
        Phases {
            gravity: model.external.gravity,
            weightless: scene.cloth.sewing.weightless,
            rest: scene.simulation.rest,
            released_by: model
                .attachments
                .iter()
                .map(|a| a.release)
                .filter(|t| t.is_finite())
                .fold(0.0, Scalar::max),
            calm_since: None,
            at_rest: None,
            speed: None,
            last: (world.x.clone(), world.time),
        }
    }

    /// Sets the gravity for the next frame: off while the garment sews
    /// weightless, the scene's after. True when it changed.
    pub(super) fn before_frame(&self, model: &mut Model, world: &World) -> bool {
        let sewing = self
            .weightless
            .is_some_and(|limit| world.time < limit && any_open(world));
        let gravity = if sewing { None } else { self.gravity };
        let changed = model.external.gravity != gravity;
        model.external.gravity = gravity;
        changed
    }

    /// Watches the frame the state is at; true when the run is at rest.
    pub(super) fn after_frame(&mut self, world: &World) -> bool {
        let (before, then) = &self.last;
        let elapsed = world.time - then;
        self.speed = (before.len() == world.x.len() && elapsed > 0.0).then(|| {
            let moved = world.x.iter().zip(before).map(|(x, y)| x.distance(*y));
            moved.fold(0.0, Scalar::max) / elapsed
        });
        self.last.0.clone_from(&world.x);
        self.last.1 = world.time;
        let Some(rest) = self.rest else {
            return false;
        };
        // The first frame, or a mesh that changed, is not calm: not yet comparable.
        let held = world.time < self.released_by;
        if self.speed.is_none_or(|speed| speed > rest.speed) || any_open(world) || held {
            self.calm_since = None;
            return false;
        }
        let since = *self.calm_since.get_or_insert(world.time);
        // The window counts whole frames: a tiny tolerance for the sum of steps.
        if world.time - since >= rest.window * (1.0 - 1e-9) {
            self.at_rest = Some(world.time);
        }
        self.at_rest.is_some()
    }

    /// The rest criterion's outcome, when the scene has one.
    pub(super) fn summary(&self) -> Option<RestSummary> {
        self.rest.map(|rest| RestSummary {
            at_rest: self.at_rest.is_some(),
            time: self.at_rest,
            speed: self.speed,
            threshold: rest.speed,
            window: rest.window,
        })
    }
}

/// True while a seam of the garment is open.
fn any_open(world: &World) -> bool {
    world.mesh.has_open_seam()
}
