//! Helpers shared by the test modules.

use drape::adapt::AdaptConfig;
use drape::math::{Scalar, Vector};
use drape::physics::{Energy, Model, SolveFailure, Stepper};
use drape::scene::Scene;
use drape::scene::{AdaptCriterion, AdaptMethod, Pin, PinMotion};
use drape::sim::{Pipeline, Setup, SimParts, SimState, build};
use drape::world::World;

/// Overrides of `scenes/hanging_sheet_rest.toml` that made the sizing
/// criterion churn at rest before bounces doubled the hysteresis
/// (`src/adapt/sizing.rs`, "Bounces"): base 8, levels up to 6, 7 / 0.7 deg,
/// `refine_strain = 0.02`, no rollback. Add the duration.
pub const BOUNCING_SHEET: [&str; 6] = [
    "cloth.resolution=8",
    "adapt.max_level=6",
    "adapt.refine_angle=7.0",
    "adapt.coarsen_angle=0.7",
    "adapt.refine_strain=0.02",
    "adapt.rollback=false",
];

/// A fixed pin on `region` with every other key at its default.
pub fn pin(region: &str) -> Pin {
    Pin {
        region: region.into(),
        box_min: None,
        box_max: None,
        disk_center: None,
        disk_radius: None,
        motion: PinMotion::Fixed,
        velocity: [0.0; 3],
        acceleration: [0.0; 3],
        center: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        angular_velocity: 0.0,
        release_time: None,
        keyframes: Vec::new(),
        easing: Default::default(),
        after_last: Default::default(),
        attach: None,
    }
}

/// Adaptivity with the papers' angle criterion as most tests use it: 15 / 1.5
/// deg, levels up to 4, a pass whenever the test calls one, no rollback. Tests
/// change what they need with `AdaptConfig { .., ..angle_config(method) }`.
pub fn angle_config(method: AdaptMethod) -> AdaptConfig {
    AdaptConfig {
        method,
        refine_angle: 15.0,
        coarsen_angle: 1.5,
        max_level: 4,
        min_edge_length: 0.0,
        every: drape::scene::AdaptEvery::Steps(1),
        rollback: false,
        max_rollbacks: 0,
        criterion: AdaptCriterion::Angle,
        hysteresis: 2.0,
        refine_strain: None,
        refine_obstacle: None,
        alternate_diagonals: true,
        gate: None,
    }
}

/// Splits, `rounds` times over, every leaf of `adapter`'s red-green hierarchy
/// whose centre (material space) lies within `radius` of `centre`, and moves
/// `world` onto the result (the second round splits the first's children).
pub fn refine_around(
    adapter: &mut drape::adapt::Adapter,
    config: &AdaptConfig,
    world: &mut World,
    (centre, radius): (drape::math::Vector2, Scalar),
    rounds: u64,
) {
    use drape::adapt::red_green::RedGreenOp;
    for round in 0..rounds {
        let hierarchy = adapter.hierarchy().expect("red-green");
        let ops: Vec<_> = hierarchy
            .leaves()
            .into_iter()
            .filter(|&l| {
                let c = hierarchy
                    .vertices(l)
                    .iter()
                    .map(|&v| world.mesh.material[v as usize])
                    .sum::<drape::math::Vector2>()
                    / 3.0;
                (c - centre).length() < radius
            })
            .map(|l| (RedGreenOp::Split(l), None))
            .collect();
        adapter
            .apply(config, world, &ops, round)
            .expect("refinement");
    }
}

/// A stepper driven without the pipeline (the physics tests step a bare world):
/// it keeps the model and the implicit warm start that [`drape::sim::Pipeline`]
/// would otherwise pass to [`Stepper`] from the run and its state.
pub struct BareStepper {
    /// The physics integrated.
    pub model: Model,
    /// The stepper itself (its fields are reachable through `Deref`).
    pub stepper: Stepper,
    /// The implicit solver's warm start (the state's, in a real run).
    pub warm_start: Vec<Vector>,
}

impl BareStepper {
    /// A stepper for `model` on the world's current mesh.
    pub fn new(model: Model, world: &World) -> BareStepper {
        let stepper = Stepper::new(&model, world);
        BareStepper {
            model,
            stepper,
            warm_start: Vec::new(),
        }
    }

    /// One step of `dt` s ([`Stepper::step`]).
    pub fn step(&mut self, world: &mut World, dt: Scalar) -> Result<(), SolveFailure> {
        self.stepper
            .step(&self.model, world, &mut self.warm_start, dt)
    }

    /// Rebuilds the elements after the mesh changed, and forgets the warm start.
    pub fn rebuild(&mut self, world: &World) {
        self.stepper.rebuild(&self.model, world);
        self.warm_start.clear();
    }

    /// The world's energies ([`Stepper::energy`]).
    pub fn energy(&self, world: &World) -> Energy {
        self.stepper.energy(&self.model, world)
    }

    /// The automatic step ([`Stepper::auto_dt`]).
    pub fn auto_dt(&self, world: &World) -> Scalar {
        self.stepper.auto_dt(&self.model, world)
    }
}

impl std::ops::Deref for BareStepper {
    type Target = Stepper;
    fn deref(&self) -> &Stepper {
        &self.stepper
    }
}

impl std::ops::DerefMut for BareStepper {
    fn deref_mut(&mut self) -> &mut Stepper {
        &mut self.stepper
    }
}

/// A scene's simulation, stepped by the run's own pipeline.
pub struct Sim {
    /// What the run holds fixed.
    pub setup: Setup,
    /// The state.
    pub state: SimState,
    /// The pipeline that steps it.
    pub pipe: Pipeline,
}

impl Sim {
    /// Builds `scene`'s simulation (panics on a scene that does not build).
    pub fn new(scene: &Scene) -> Sim {
        let SimParts {
            setup,
            state,
            pipeline: pipe,
        } = build(&scene.resolve().expect("resolve")).expect("simulation");
        Sim { setup, state, pipe }
    }

    /// Every frame of `scene` (the one this simulation was built from), as a
    /// run steps them (panics on a frame that fails).
    pub fn run_frames(&mut self, scene: &Scene) {
        let interval = scene.simulation.frame_interval();
        for frame in 0..scene.simulation.frame_count() {
            if let Err(e) = self
                .pipe
                .advance_frame(&self.setup, &mut self.state, interval)
            {
                panic!("frame {frame}: {e}");
            }
        }
    }

    /// One step of `h` seconds (panics when it is rejected).
    pub fn step(&mut self, h: Scalar) {
        if let Err(e) = self.pipe.step(&self.setup, &mut self.state, h) {
            panic!("step rejected: {e}");
        }
    }
}
