//! The swinging sheet of the implicit benchmarks (`implicit`, `assembly`): a 1 m
//! sheet of the default fabric (0.15 kg/m^2, 200 N/m as springs, 1e-5 N m,
//! damping 0.001 s, drag) pinned at two corners and swinging under gravity, at
//! `dt = 1/120` s (the step of `drape_sphere`), after 30 warm-up steps so that it
//! is already falling and folding.

use std::hint::black_box;

use drape::math::{Scalar, Vector};
use drape::physics::{
    BendingMatrix, ExternalForces, MaterialParams, Model, Solver, SolverSettings, Stepper,
};
use drape::scene::{BendingModel, DiagonalPattern, Integrator, Pin, PinMotion, StiffnessRule};
use drape::world::World;

/// The step, s.
pub const DT: Scalar = 1.0 / 120.0;

/// A pin holding the named corner in place.
fn corner(region: &str) -> Pin {
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

/// The quasi-Newton solver's iteration cap on the bench sheet: as with
/// `cg_max_iterations`, high enough that every step of the fixed `DT` solves
/// (the scenes' default of 200 is not, on this sheet).
pub const QUASI_NEWTON_ITERATIONS: u32 = 5000;

/// The swinging sheet at `resolution` with `bending`, after 30 steps, with its
/// stepper (the `assembly` bench, which sets the bending matrix, does not
/// use it).
#[allow(dead_code)]
pub fn setup(
    resolution: u32,
    bending: BendingModel,
    solver: Solver,
    refactor_iterations: u32,
) -> Sheet {
    setup_with(
        resolution,
        bending,
        solver,
        refactor_iterations,
        BendingMatrix::default(),
    )
}

/// As [`setup`], with the direct solver's `bending_matrix`.
pub fn setup_with(
    resolution: u32,
    bending: BendingModel,
    solver: Solver,
    refactor_iterations: u32,
    bending_matrix: BendingMatrix,
) -> Sheet {
    let mesh = drape::mesh::rectangle(1.0, 1.0, resolution, DiagonalPattern::Alternating)
        .expect("valid rectangle");
    let x = mesh.material.iter().map(|p| p.extend(1.0)).collect();
    let mut world = World::new(mesh, x);
    let pins = [corner("corner:top_left"), corner("corner:top_right")];
    world.pins = drape::pins::Pins::select(&pins, &world.mesh, &world.x).expect("pins");
    let model = Model {
        material: MaterialParams {
            density: 0.15,
            stretch: 200.0,
            membrane: drape::physics::Membrane::Springs,
            bending: 1e-5,
            damping: 0.001,
            bending_model: bending,
            stiffness_rule: StiffnessRule::Consistent,
            sewing: Default::default(),
        },
        external: ExternalForces {
            gravity: Some(Vector::new(0.0, 0.0, -9.81)),
            drag: Some(0.02),
            ..Default::default()
        },
        integrator: Integrator::Implicit,
        cg_tolerance: 1e-6,
        cg_max_iterations: 5000,
        attachments: Vec::new(),
        solver: SolverSettings {
            solver,
            refactor_iterations,
            bending_matrix,
            quasi_newton_iterations: QUASI_NEWTON_ITERATIONS,
            ..SolverSettings::default()
        },
    };
    let stepper = Stepper::new(&model, &world);
    let mut sheet = Sheet {
        world,
        model,
        stepper,
        warm_start: Vec::new(),
    };
    for _ in 0..30 {
        sheet.step();
    }
    sheet
}

/// A bench sheet: the world, its model, its stepper and the implicit warm start
/// (the simulation state's, in a run).
pub struct Sheet {
    /// The sheet's mesh and state.
    pub world: World,
    /// Its material, forces and solver.
    pub model: Model,
    /// Its elements and the solver's scratch.
    pub stepper: Stepper,
    /// The last step's velocity change.
    pub warm_start: Vec<Vector>,
}

impl Sheet {
    /// One implicit step of `DT`.
    pub fn step(&mut self) {
        self.stepper
            .step(
                &self.model,
                black_box(&mut self.world),
                &mut self.warm_start,
                DT,
            )
            .expect("solved");
    }
}
